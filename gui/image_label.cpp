#include "gui/image_label.h"

#include <QPixmap>
#include <QResizeEvent>

namespace nadir::gui {

ImageLabel::ImageLabel(QWidget* parent, const QString& placeholder) : QLabel(placeholder, parent) {
  setAlignment(Qt::AlignCenter);
  setMinimumSize(320, 240);
  setStyleSheet(QStringLiteral("background-color: #202020; color: #c0c0c0;"));
  setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Ignored);
}

void ImageLabel::setImage(const QImage& image) {
  image_ = image;
  rescale();
}

void ImageLabel::resizeEvent(QResizeEvent* event) {
  QLabel::resizeEvent(event);
  rescale();
}

void ImageLabel::rescale() {
  if (image_.isNull()) {
    setPixmap(QPixmap());
    return;
  }
  setPixmap(
      QPixmap::fromImage(image_.scaled(size(), Qt::KeepAspectRatio, Qt::SmoothTransformation)));
}

}  // namespace nadir::gui
