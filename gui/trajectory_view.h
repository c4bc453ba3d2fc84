#pragma once
// nadir-viewer's 3D view: the scenario's terrain (render::TerrainRenderer, the one
// the camera node renders with), every run's truth as a red ribbon and each
// estimate source in its nadir-plot colour, drawn up to the playback time, and
// the first run's vehicle at its truth position. Left drag rotates, right drag
// pans, the wheel zooms; in follow mode the camera orbits the vehicle.
//
// Needs an OpenGL 4.5 core default surface format (set before QApplication).

#include <QColor>
#include <QOpenGLWidget>
#include <QPoint>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gui/run_data.h"
#include "gui/viewer_model.h"
#include "render/terrain_renderer.h"
#include "terrain/targets.h"
#include "terrain/tiles.h"
#include "terrain/world_factory.h"

namespace nadir::gui {

// What the view draws the ground from; without one the ground is left plain.
struct ViewerTerrain {
  terrain::BuiltWorld built;
  std::shared_ptr<terrain::TileTree> tiles;
  render::TerrainRendererParams renderer;
  // The scenario's ground targets, drawn on the terrain as the camera sees them.
  std::vector<terrain::GroundTarget> targets;
  std::string scenario_path;  // the scenario it was built from
  std::string world;          // its world as worldOfScenario gives it
};

// Builds the terrain of a scenario (a run's scenario.yaml, a file or a built-in
// name) from its world, tiles, renderer and targets; throws core::ParamError
// naming the file and key, or what makeWorld throws.
ViewerTerrain terrainOfScenario(const std::string& scenario_yaml);

// The world a scenario flies over (its world parameters: kind, seed, files,
// origin) as text: two runs whose scenarios give the same text share one world
// frame and terrain. Throws what loadScenario throws.
std::string worldOfScenario(const std::string& scenario_yaml);

// The default surface format the view needs (OpenGL 4.5 core, a depth buffer);
// call before the QApplication exists.
void setViewerSurfaceFormat();

// The truth's colour: red for the first run, other reds for the next runs.
QColor truthColor(std::size_t run_index);

class TrajectoryView : public QOpenGLWidget {
 public:
  // runs must outlive the view (it may grow); the camera starts fitted to every truth.
  TrajectoryView(const std::vector<RunData>& runs, std::optional<ViewerTerrain> terrain,
                 QWidget* parent = nullptr);
  ~TrajectoryView() override;
  TrajectoryView(const TrajectoryView&) = delete;
  TrajectoryView& operator=(const TrajectoryView&) = delete;

  // Playback time, s since each run's truth start.
  void setTime(double t_s);
  double time() const { return time_s_; }
  void setFollow(bool follow);
  // Fits the camera to every truth; false (camera kept) while there is none.
  bool fitToRuns();
  // Replaces the terrain drawn (nothing: plain ground).
  void setTerrain(std::optional<ViewerTerrain> terrain);
  bool hasTerrain() const { return terrain_.has_value(); }
  // The terrain drawn, null if none.
  const ViewerTerrain* terrain() const { return terrain_ ? &*terrain_ : nullptr; }
  // True once a drag or the wheel has moved the camera.
  bool cameraMovedByUser() const { return camera_moved_; }
  bool follow() const { return follow_; }
  OrbitCamera& camera() { return camera_; }
  // The camera the next frame is drawn from (the vehicle as target in follow mode).
  OrbitCamera frameCamera() const;
  // The first run's truth at the playback time; nothing outside its span.
  std::optional<Eigen::Vector3d> vehiclePosition() const;
  // Why the terrain is not drawn (no GL 4.5 core context, ...); empty if it is.
  const std::string& terrainError() const { return terrain_error_; }
  // Size of the drawn framebuffer, device pixels.
  int framebufferWidth() const;
  int framebufferHeight() const;

 protected:
  void initializeGL() override;
  void paintGL() override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;

 private:
  struct Gl;
  void releaseGl();
  void createTerrainRenderer();

  const std::vector<RunData>& runs_;
  std::optional<ViewerTerrain> terrain_;
  std::unique_ptr<Gl> gl_;
  OrbitCamera camera_;
  double time_s_ = 0.0;
  bool follow_ = false;
  bool camera_moved_ = false;
  QPoint last_mouse_;
  std::string terrain_error_;
};

}  // namespace nadir::gui
