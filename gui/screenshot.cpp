#include "gui/screenshot.h"

#include <QApplication>
#include <QPixmap>
#include <QString>
#include <QTimer>
#include <QWidget>

#include <cmath>
#include <cstdio>
#include <utility>

namespace nadir::gui {

void screenshotAfter(QWidget& window, double wait_s, const std::string& png_path,
                     const std::string& program, std::function<void()> report) {
  const int wait_ms = static_cast<int>(std::lround(wait_s * 1000));
  QTimer::singleShot(wait_ms, &window, [&window, png_path, program, report = std::move(report)] {
    if (!window.grab().save(QString::fromStdString(png_path))) {
      std::fprintf(stderr, "%s: cannot write %s\n", program.c_str(), png_path.c_str());
      QApplication::exit(1);
      return;
    }
    if (report) report();
    QApplication::exit(0);
  });
}

}  // namespace nadir::gui
