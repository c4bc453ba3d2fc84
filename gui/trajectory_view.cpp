// render/gl.h first: it asks GL/glext.h for the core prototypes before Qt includes GL.
#include "render/gl.h"

#include "gui/trajectory_view.h"

#include <QColor>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QSurfaceFormat>
#include <QWheelEvent>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>

#include "core/params.h"
#include "gui/plots.h"
#include "nodes/scenario_files.h"

namespace nadir::gui {
namespace {

constexpr double kTruthWidthPx = 4.0;
constexpr double kSourceWidthPx = 2.0;
constexpr double kMarkerHalfPx = 6.0;
constexpr double kEstimateHalfPx = 3.0;
constexpr double kVehicleLengthPx = 30.0;
constexpr double kNearM = 0.5;

const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec2 position;
layout(location = 1) in vec4 color;
out vec4 vertex_color;
void main() {
  vertex_color = color;
  gl_Position = vec4(position, 0.0, 1.0);
})";

const char* kFragmentShader = R"(#version 450 core
in vec4 vertex_color;
out vec4 out_color;
void main() { out_color = vertex_color; })";

// Triangles in normalised device coordinates, drawn in pixels: x right and y down
// from the top-left pixel's centre, as CameraIntrinsics::project gives them.
class Overlay {
 public:
  Overlay(const OrbitCamera& camera, int width, int height)
      : camera_from_world_(camera.worldFromCamera().inverse()),
        intrinsics_(camera.intrinsics(width, height)),
        width_(width),
        height_(height) {}

  void polyline(const std::vector<Eigen::Vector3d>& points, const QColor& color, double width_px) {
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
      segment(points[i], points[i + 1], color, width_px);
    }
  }

  void square(const Eigen::Vector3d& p_world, const QColor& color, double half_px) {
    const Eigen::Vector3d p = camera_from_world_ * p_world;
    if (p.z() <= kNearM) return;
    const Eigen::Vector2d c = intrinsics_.project(p);
    quad(c + Eigen::Vector2d(-half_px, -half_px), c + Eigen::Vector2d(half_px, -half_px),
         c + Eigen::Vector2d(half_px, half_px), c + Eigen::Vector2d(-half_px, half_px), color);
  }

  // An arrowhead in the body's x-y plane at p_world, nose along body x, length_px
  // long on screen; p_world lies inside it.
  void vehicle(const Eigen::Vector3d& p_world, const Eigen::Quaterniond& q_world_body,
               double length_px, const QColor& color) {
    const Eigen::Vector3d p = camera_from_world_ * p_world;
    if (p.z() <= kNearM) return;
    const double length_m = length_px * p.z() / intrinsics_.fx;
    const Eigen::Matrix3d R = q_world_body.toRotationMatrix();
    const auto body = [&](double x, double y) {
      return Eigen::Vector3d(p_world + R * Eigen::Vector3d(x * length_m, y * length_m, 0.0));
    };
    triangle(body(kNose, 0), body(kWing, -kSpan), body(kTail, 0), color);
    triangle(body(kNose, 0), body(kTail, 0), body(kWing, kSpan), color);
  }

  const std::vector<float>& vertices() const { return vertices_; }

  // The vehicle's shape, in lengths from its position along body x and y.
  static constexpr double kNose = 0.6;
  static constexpr double kWing = -0.4;
  static constexpr double kSpan = 0.45;
  static constexpr double kTail = -0.2;

 private:
  void segment(const Eigen::Vector3d& a_world, const Eigen::Vector3d& b_world, const QColor& color,
               double width_px) {
    Eigen::Vector3d a = camera_from_world_ * a_world;
    Eigen::Vector3d b = camera_from_world_ * b_world;
    if (a.z() <= kNearM && b.z() <= kNearM) return;
    // Cut the part behind the near plane: projecting it would mirror it.
    if (a.z() < kNearM) a = b + (a - b) * (b.z() - kNearM) / (b.z() - a.z());
    if (b.z() < kNearM) b = a + (b - a) * (a.z() - kNearM) / (a.z() - b.z());
    const Eigen::Vector2d pa = intrinsics_.project(a);
    const Eigen::Vector2d pb = intrinsics_.project(b);
    const Eigen::Vector2d d = pb - pa;
    const double length = d.norm();
    if (!std::isfinite(length)) return;
    const Eigen::Vector2d along =
        length > 1e-9 ? Eigen::Vector2d(d / length) : Eigen::Vector2d(1, 0);
    const Eigen::Vector2d n = Eigen::Vector2d(-along.y(), along.x()) * (width_px / 2.0);
    // Half a width past each end closes the joints between segments.
    const Eigen::Vector2d e = along * (width_px / 2.0);
    quad(pa - e + n, pb + e + n, pb + e - n, pa - e - n, color);
  }

  void triangle(const Eigen::Vector3d& a_world, const Eigen::Vector3d& b_world,
                const Eigen::Vector3d& c_world, const QColor& color) {
    const Eigen::Vector3d a = camera_from_world_ * a_world;
    const Eigen::Vector3d b = camera_from_world_ * b_world;
    const Eigen::Vector3d c = camera_from_world_ * c_world;
    if (a.z() <= kNearM || b.z() <= kNearM || c.z() <= kNearM) return;
    for (const Eigen::Vector3d* q : {&a, &b, &c}) vertex(intrinsics_.project(*q), color);
  }

  void quad(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
            const Eigen::Vector2d& d, const QColor& color) {
    for (const Eigen::Vector2d* p : {&a, &b, &c, &a, &c, &d}) vertex(*p, color);
  }

  void vertex(const Eigen::Vector2d& px, const QColor& color) {
    vertices_.push_back(static_cast<float>(2.0 * (px.x() + 0.5) / width_ - 1.0));
    vertices_.push_back(static_cast<float>(1.0 - 2.0 * (px.y() + 0.5) / height_));
    vertices_.push_back(static_cast<float>(color.redF()));
    vertices_.push_back(static_cast<float>(color.greenF()));
    vertices_.push_back(static_cast<float>(color.blueF()));
    vertices_.push_back(static_cast<float>(color.alphaF()));
  }

  Eigen::Isometry3d camera_from_world_;
  render::CameraIntrinsics intrinsics_;
  int width_;
  int height_;
  std::vector<float> vertices_;
};

}  // namespace

void setViewerSurfaceFormat() {
  QSurfaceFormat format;
  format.setVersion(4, 5);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  QSurfaceFormat::setDefaultFormat(format);
}

QColor truthColor(std::size_t run_index) {
  static const std::array<QColor, 4> kReds = {QColor(255, 0, 0), QColor(190, 0, 0),
                                              QColor(255, 90, 90), QColor(130, 0, 0)};
  return kReds[run_index % kReds.size()];
}

namespace {

// The parts of a scenario the viewer draws; the rest of the file is not read.
struct ScenarioTerrain {
  terrain::WorldParams world;
  terrain::TileParams tiles;
  render::TerrainRendererParams renderer;
  std::map<std::string, terrain::GroundTarget> targets;

  void visit(core::ParamVisitor& v) {
    core::visitGroup(v, "world", "the terrain", world);
    core::visitGroup(v, "tiles", "terrain tiles", tiles);
    core::visitGroup(v, "renderer", "terrain drawing", renderer);
    core::visitGroupMap(v, "targets", "ground targets", targets);
  }
};

ScenarioTerrain readScenarioTerrain(const std::string& name_or_path) {
  const std::string path = nodes::resolveScenarioPath(name_or_path);
  ScenarioTerrain params;
  core::applyYamlFileKeys(path, {"world", "tiles", "renderer", "targets"},
                          [&params](core::ParamVisitor& v) { params.visit(v); });
  terrain::resolvePathsFrom(params.world, std::filesystem::path(path).parent_path().string());
  return params;
}

}  // namespace

ViewerTerrain terrainOfScenario(const std::string& scenario_yaml) {
  ScenarioTerrain params = readScenarioTerrain(scenario_yaml);
  ViewerTerrain terrain;
  terrain.built = terrain::makeWorld(params.world);
  terrain.tiles = std::make_shared<terrain::TileTree>(terrain.built.world, params.tiles);
  terrain.renderer = params.renderer;
  for (const auto& [name, target] : params.targets) terrain.targets.push_back(target);
  terrain::resolveGeodeticTargets(terrain.targets, core::LocalNedFrame(terrain.built.origin));
  terrain.scenario_path = scenario_yaml;
  terrain.world = core::formatParamsOf(params.world);
  return terrain;
}

std::string worldOfScenario(const std::string& scenario_yaml) {
  ScenarioTerrain params = readScenarioTerrain(scenario_yaml);
  return core::formatParamsOf(params.world);
}

struct TrajectoryView::Gl {
  std::unique_ptr<render::TerrainRenderer> terrain;
  // The terrain renderer puts image row 0 at the framebuffer's bottom (for
  // glReadPixels); it draws here and is blitted upside down into the widget.
  GLuint framebuffer = 0;
  GLuint color = 0;
  GLuint depth = 0;
  int width = 0;
  int height = 0;
  GLuint program = 0;
  GLuint vertex_array = 0;
  GLuint vertex_buffer = 0;

  ~Gl() {
    terrain.reset();
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteRenderbuffers(1, &color);
    glDeleteRenderbuffers(1, &depth);
    glDeleteProgram(program);
    glDeleteVertexArrays(1, &vertex_array);
    glDeleteBuffers(1, &vertex_buffer);
  }

  void resize(int w, int h) {
    if (w == width && h == height) return;
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteRenderbuffers(1, &color);
    glDeleteRenderbuffers(1, &depth);
    glCreateRenderbuffers(1, &color);
    glNamedRenderbufferStorage(color, GL_RGBA8, w, h);
    glCreateRenderbuffers(1, &depth);
    glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT24, w, h);
    glCreateFramebuffers(1, &framebuffer);
    glNamedFramebufferRenderbuffer(framebuffer, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    glNamedFramebufferRenderbuffer(framebuffer, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    width = w;
    height = h;
  }
};

TrajectoryView::TrajectoryView(const std::vector<RunData>& runs,
                               std::optional<ViewerTerrain> terrain, QWidget* parent)
    : QOpenGLWidget(parent), runs_(runs), terrain_(std::move(terrain)) {
  fitToRuns();
  setMinimumSize(320, 240);
}

bool TrajectoryView::fitToRuns() {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const RunData& run : runs_) {
    for (const core::StampedPose& pose : run.truth) {
      const Eigen::Vector3d& p = pose.p_ned_m;
      if (!p.allFinite()) continue;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  if (!lo.allFinite()) return false;
  camera_.fit(lo, hi);
  update();
  return true;
}

void TrajectoryView::setTerrain(std::optional<ViewerTerrain> terrain) {
  terrain_ = std::move(terrain);
  terrain_error_.clear();
  if (gl_) {
    makeCurrent();
    createTerrainRenderer();
    doneCurrent();
  }
  update();
}

void TrajectoryView::createTerrainRenderer() {
  gl_->terrain.reset();
  if (!terrain_) return;
  // Without the terrain the trajectories are still worth showing.
  try {
    gl_->terrain = std::make_unique<render::TerrainRenderer>(terrain_->tiles, terrain_->renderer);
    gl_->terrain->setTargets(terrain_->targets);
  } catch (const std::exception& e) {
    gl_->terrain.reset();
    terrain_error_ = e.what();
    std::fprintf(stderr, "nadir-viewer: no terrain: %s\n", e.what());
  }
}

TrajectoryView::~TrajectoryView() { releaseGl(); }

void TrajectoryView::releaseGl() {
  if (!gl_) return;
  makeCurrent();
  gl_.reset();
  doneCurrent();
}

void TrajectoryView::setTime(double t_s) {
  time_s_ = t_s;
  update();
}

void TrajectoryView::setFollow(bool follow) {
  follow_ = follow;
  update();
}

OrbitCamera TrajectoryView::frameCamera() const {
  OrbitCamera camera = camera_;
  if (follow_) {
    if (const auto vehicle = vehiclePosition()) camera.target = *vehicle;
  }
  return camera;
}

std::optional<Eigen::Vector3d> TrajectoryView::vehiclePosition() const {
  if (runs_.empty()) return std::nullopt;
  return positionAt(runs_.front().truth, runs_.front().t0_s + time_s_);
}

int TrajectoryView::framebufferWidth() const {
  return static_cast<int>(std::lround(width() * devicePixelRatioF()));
}

int TrajectoryView::framebufferHeight() const {
  return static_cast<int>(std::lround(height() * devicePixelRatioF()));
}

void TrajectoryView::initializeGL() {
  gl_ = std::make_unique<Gl>();
  // The context may go before the widget (reparenting): free the GL objects then.
  connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, [this] { releaseGl(); });
  createTerrainRenderer();
  gl_->program = render::linkProgram("viewer overlay", kVertexShader, kFragmentShader);
  glCreateVertexArrays(1, &gl_->vertex_array);
  glCreateBuffers(1, &gl_->vertex_buffer);
  constexpr GLsizei kStride = 6 * sizeof(float);
  glVertexArrayVertexBuffer(gl_->vertex_array, 0, gl_->vertex_buffer, 0, kStride);
  glEnableVertexArrayAttrib(gl_->vertex_array, 0);
  glVertexArrayAttribFormat(gl_->vertex_array, 0, 2, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(gl_->vertex_array, 0, 0);
  glEnableVertexArrayAttrib(gl_->vertex_array, 1);
  glVertexArrayAttribFormat(gl_->vertex_array, 1, 4, GL_FLOAT, GL_FALSE, 2 * sizeof(float));
  glVertexArrayAttribBinding(gl_->vertex_array, 1, 0);
}

void TrajectoryView::paintGL() {
  const int w = framebufferWidth();
  const int h = framebufferHeight();
  const OrbitCamera camera = frameCamera();
  const GLuint target = defaultFramebufferObject();
  glViewport(0, 0, w, h);
  if (gl_->terrain) {
    gl_->resize(w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, gl_->framebuffer);
    render::DrawView view;
    view.T_world_cam = camera.worldFromCamera();
    view.intrinsics = camera.intrinsics(w, h);
    view.near_m = kNearM;
    view.far_m = std::max(20000.0, 4.0 * camera.distance_m);
    view.gray = false;
    gl_->terrain->draw(view);
    glBlitNamedFramebuffer(gl_->framebuffer, target, 0, 0, w, h, 0, h, w, 0, GL_COLOR_BUFFER_BIT,
                           GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, target);
  } else {
    glClearColor(0.2f, 0.2f, 0.22f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }

  // The wider truths first, the estimates over them (an estimate close to the
  // truth stays visible along its middle), the vehicle on top: trajectories are
  // never hidden by the terrain.
  Overlay overlay(camera, w, h);
  for (std::size_t r = 0; r < runs_.size(); ++r) {
    for (const auto& line : trackUpTo(runs_[r].truth, runs_[r].t0_s + time_s_)) {
      overlay.polyline(line, truthColor(r), kTruthWidthPx);
    }
  }
  for (const RunData& run : runs_) {
    for (const auto& [name, source] : run.sources) {
      const QColor color = sourceColor(run, name);
      for (const auto& line : trackUpTo(source, run.t0_s + time_s_)) {
        overlay.polyline(line, color, kSourceWidthPx);
      }
    }
  }
  // Where each estimate is now, then the vehicle with its attitude.
  for (const RunData& run : runs_) {
    for (const auto& [name, source] : run.sources) {
      if (const auto p = positionAt(source, run.t0_s + time_s_)) {
        overlay.square(*p, Qt::black, kEstimateHalfPx + 1.0);
        overlay.square(*p, sourceColor(run, name), kEstimateHalfPx);
      }
    }
  }
  if (const auto vehicle = vehiclePosition()) {
    const auto attitude = attitudeAt(runs_.front().truth, runs_.front().t0_s + time_s_);
    if (attitude) {
      overlay.vehicle(*vehicle, *attitude, kVehicleLengthPx + 6.0, Qt::black);
      overlay.vehicle(*vehicle, *attitude, kVehicleLengthPx, Qt::yellow);
    } else {
      overlay.square(*vehicle, Qt::black, kMarkerHalfPx + 1.5);
      overlay.square(*vehicle, Qt::yellow, kMarkerHalfPx);
    }
  }
  const std::vector<float>& vertices = overlay.vertices();
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  if (!vertices.empty()) {
    glNamedBufferData(gl_->vertex_buffer, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
                      vertices.data(), GL_STREAM_DRAW);
    glUseProgram(gl_->program);
    glBindVertexArray(gl_->vertex_array);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(vertices.size() / 6));
    glBindVertexArray(0);
    glUseProgram(0);
  }
}

void TrajectoryView::mousePressEvent(QMouseEvent* event) {
  last_mouse_ = event->position().toPoint();
}

void TrajectoryView::mouseMoveEvent(QMouseEvent* event) {
  const QPoint now = event->position().toPoint();
  const QPoint d = now - last_mouse_;
  last_mouse_ = now;
  if (event->buttons() & Qt::LeftButton) {
    camera_.rotate(d.x(), d.y());
  } else if (event->buttons() & (Qt::RightButton | Qt::MiddleButton)) {
    camera_.pan(d.x(), d.y(), height());
  } else {
    return;
  }
  camera_moved_ = true;
  update();
}

void TrajectoryView::wheelEvent(QWheelEvent* event) {
  // One wheel notch (120) zooms by 15 %.
  camera_.zoom(std::pow(0.85, event->angleDelta().y() / 120.0));
  camera_moved_ = true;
  update();
}

}  // namespace nadir::gui
