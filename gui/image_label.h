#pragma once
// A QLabel that shows its image scaled to its size, keeping the aspect ratio
// (the viewer's camera pane, the calibration window's images).

#include <QImage>
#include <QLabel>

namespace nadir::gui {

class ImageLabel : public QLabel {
 public:
  explicit ImageLabel(QWidget* parent, const QString& placeholder = {});
  // A null image clears the picture (the label's text shows again).
  void setImage(const QImage& image);

 protected:
  void resizeEvent(QResizeEvent* event) override;

 private:
  void rescale();
  QImage image_;
};

}  // namespace nadir::gui
