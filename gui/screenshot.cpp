#include "gui/screenshot.h"

#include <QApplication>
#include <QPixmap>
#include <QString>
#include <QTimer>
#include <QWidget>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

namespace nadir::gui {

namespace {

void saveAndExit(QWidget& window, const std::string& png_path, const std::string& program,
                 const std::function<void()>& report) {
  if (!window.grab().save(QString::fromStdString(png_path))) {
    std::fprintf(stderr, "%s: cannot write %s\n", program.c_str(), png_path.c_str());
    QApplication::exit(1);
    return;
  }
  if (report) report();
  QApplication::exit(0);
}

}  // namespace

void screenshotAfter(QWidget& window, double wait_s, const std::string& png_path,
                     const std::string& program, std::function<void()> report) {
  const int wait_ms = static_cast<int>(std::lround(wait_s * 1000));
  QTimer::singleShot(wait_ms, &window, [&window, png_path, program, report = std::move(report)] {
    saveAndExit(window, png_path, program, report);
  });
}

void screenshotWhen(QWidget& window, std::function<bool()> ready, double wait_s,
                    const std::string& png_path, const std::string& program,
                    std::function<void()> report) {
  auto* poll = new QTimer(&window);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  QObject::connect(poll, &QTimer::timeout, &window,
                   [&window, poll, deadline, ready = std::move(ready), png_path, program,
                    report = std::move(report)] {
                     if (!ready() && std::chrono::steady_clock::now() < deadline) return;
                     poll->stop();
                     saveAndExit(window, png_path, program, report);
                   });
  poll->start(100);
}

}  // namespace nadir::gui
