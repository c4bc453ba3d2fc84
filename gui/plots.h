#pragma once
// The plot viewer's charts of a run (Qt Charts), shared by the headless renderer
// and the interactive viewer. Truth is always black, each source keeps its own
// colour in every chart and, by its name, in every run.
// Time axes show seconds since the truth's first pose.

#include <QChart>
#include <QColor>

#include <memory>
#include <set>
#include <string>
#include <vector>

#include "gui/run_data.h"

class QValueAxis;
class QWidget;

namespace nadir::gui {

// The colour of an estimate source in every chart (and in nadir-viewer).
QColor sourceColor(const RunData& run, const std::string& name);

// The truth's legend entry: "truth", or "NAME (truth)" when another trajectory
// than the recorded truth was chosen.
QString truthLabel(const RunData& run);
// A source's legend entry: its name, "truth (recorded)" for the recorded truth
// when another trajectory is the truth.
QString sourceLabel(const RunData& run, const std::string& name);

// Trajectories left out of the figures, by name (the truth's included).
using HiddenTrajectories = std::set<std::string>;

// Charts shown together, stacked top to bottom.
struct Figure {
  std::string name;  // a file stem: position, attitude, error, top_view
  std::vector<std::unique_ptr<QChart>> charts;
};

// north x, east y, down z against time (truth and each source).
Figure positionFigure(const RunData& run, const HiddenTrajectories& hidden = {});
// roll, pitch, yaw against time (truth and each source).
Figure attitudeFigure(const RunData& run, const HiddenTrajectories& hidden = {});
// Each source's position error norm against time.
Figure errorFigure(const RunData& run, const HiddenTrajectories& hidden = {});
// East against north, the same metres per pixel on both axes whatever the size,
// zoom or pan: a range set on one axis (a zoom rectangle of any shape) widens the
// other about its centre to match.
Figure topViewFigure(const RunData& run, const HiddenTrajectories& hidden = {});
// The four above, in that order.
std::vector<Figure> buildFigures(const RunData& run, const HiddenTrajectories& hidden = {});

// Tick spacing aimed at: wide enough for a label across, closer up the side (a
// chart of three stacked in a window is not 150 px high).
inline constexpr double kHorizontalTickSpacingPx = 90.0;
inline constexpr double kVerticalTickSpacingPx = 50.0;

// A round tick step (1, 2 or 5 times a power of ten) giving ticks about
// spacing_px apart over a span of span_units shown on length_px pixels.
double roundTickStep(double span_units, double length_px,
                     double spacing_px = kHorizontalTickSpacingPx);
// printf format of tick labels at that step: no more decimals than it has.
QString tickLabelFormat(double step);
// Keeps the axis's ticks at round multiples of roundTickStep whenever its range
// or the chart's plot area changes (zoom, pan, resize).
void keepRoundTicks(QChart* chart, QValueAxis* axis);

// A widget showing the figure's charts, which it takes over.
std::unique_ptr<QWidget> figureWidget(Figure figure);

// Renders the figure to a width x height PNG. Needs a QApplication. Throws
// RunDataError naming the path if it cannot write it.
void renderFigurePng(Figure figure, const std::string& path, int width, int height);

}  // namespace nadir::gui
