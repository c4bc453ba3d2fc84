// nadir-viewer's window on a real run (made by `nadir run`, see CMakeLists.txt) on a
// display with OpenGL 4.5 core: seeking, the time readout, the vehicle marker
// against the truth, playback, a rendered frame whose red ribbon lies where the
// projection of the truth says, the terrain of any run, and live mode's Reset VO.
#include "gui/viewer_window.h"

#include <QAction>
#include <QApplication>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QImage>
#include <QMenu>
#include <QMouseEvent>
#include <QToolButton>
#include <QWheelEvent>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "gui/live_feed.h"
#include "gui/run_data.h"
#include "gui/trajectory_view.h"
#include "gui/vo_reset_sender.h"
#include "gui_test_util.h"
#include "lcmtypes/bus_io.h"
#include "nadir/image_t.hpp"
#include "nadir/pose_t.hpp"
#include "nadir/vo_estimate_t.hpp"
#include "tests/support/lcm_messages.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 640;
constexpr int kHeight = 480;

class GuiViewerWindow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (QApplication::instance() != nullptr) return;
    setViewerSurfaceFormat();
    static int argc = 1;
    static char name[] = "gui_viewer_window_test";
    static char* argv[] = {name, nullptr};
    // Never destroyed: Qt must outlive every test, and ends with the process.
    new QApplication(argc, argv);
  }

  static std::string runDir() { return NADIR_VIEWER_RUN_DIR; }

  static std::unique_ptr<ViewerWindow> open(const std::vector<std::string>& dirs) {
    std::vector<RunData> runs;
    for (const std::string& dir : dirs) runs.push_back(loadRun(dir));
    auto window = std::make_unique<ViewerWindow>(
        std::move(runs), terrainOfScenario((fs::path(dirs.front()) / "scenario.yaml").string()));
    window->show();
    window->view().setFixedSize(kWidth, kHeight);
    settle();
    return window;
  }

  static void settle() {
    for (int i = 0; i < 5; ++i) QApplication::processEvents();
  }
};

// The truth at t (s since its start), interpolated here without the viewer's code.
Eigen::Vector3d truthAt(const RunData& run, double t) {
  const core::Trajectory& s = run.truth;
  const double stamp = run.t0_s + t;
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (s[i].t_s >= stamp) {
      const double a = (stamp - s[i - 1].t_s) / (s[i].t_s - s[i - 1].t_s);
      return s[i - 1].p_ned_m + a * (s[i].p_ned_m - s[i - 1].p_ned_m);
    }
  }
  return s.back().p_ned_m;
}

bool isRed(QRgb c) { return qRed(c) > 200 && qGreen(c) < 60 && qBlue(c) < 60; }
bool isYellow(QRgb c) { return qRed(c) > 200 && qGreen(c) > 200 && qBlue(c) < 60; }

// True if a pixel matching within radius px of (u, v) exists.
template <class Match>
bool near(const QImage& image, const Eigen::Vector2d& uv, int radius, Match match) {
  const int u0 = static_cast<int>(std::lround(uv.x()));
  const int v0 = static_cast<int>(std::lround(uv.y()));
  for (int v = v0 - radius; v <= v0 + radius; ++v) {
    for (int u = u0 - radius; u <= u0 + radius; ++u) {
      if (image.valid(u, v) && match(image.pixel(u, v))) return true;
    }
  }
  return false;
}

TEST_F(GuiViewerWindow, SeekShowsTheTimeAndTheVehicleAtTheTruth) {
  const auto window = open({runDir()});
  const RunData& run = window->runs().front();
  EXPECT_NEAR(window->duration(), run.truth.back().t_s - run.t0_s, 1e-9);
  for (double t : {0.0, 1.2345, 4.321, 7.77}) {
    window->seek(t);
    EXPECT_DOUBLE_EQ(window->time(), t);
    EXPECT_EQ(window->timeText(), QString::asprintf("%.2f s / %.2f s", t, window->duration()));
    const auto vehicle = window->view().vehiclePosition();
    ASSERT_TRUE(vehicle);
    EXPECT_LT((*vehicle - truthAt(run, t)).norm(), 1e-6) << t;
  }
  window->seek(1e9);
  EXPECT_DOUBLE_EQ(window->time(), window->duration());
  window->seek(-3.0);
  EXPECT_DOUBLE_EQ(window->time(), 0.0);
}

// A typed time and the keyboard's steps skip there, within the playback span.
TEST_F(GuiViewerWindow, SkipsToATypedTimeAndStepsByKey) {
  const auto window = open({runDir()});
  auto* go_to = window->findChild<QDoubleSpinBox*>();
  ASSERT_NE(go_to, nullptr);
  go_to->setValue(3.25);
  emit go_to->editingFinished();
  EXPECT_DOUBLE_EQ(window->time(), 3.25);
  EXPECT_EQ(window->timeText(), QString::asprintf("3.25 s / %.2f s", window->duration()));
  const auto press = [&](const QKeySequence& keys) {
    for (QAction* action : window->actions()) {
      if (action->shortcut() == keys) action->trigger();
    }
  };
  press(QKeySequence(Qt::Key_Right));
  EXPECT_DOUBLE_EQ(window->time(), 4.25);
  press(QKeySequence(Qt::SHIFT | Qt::Key_Left));
  EXPECT_DOUBLE_EQ(window->time(), 0.0);
  press(QKeySequence(Qt::Key_End));
  EXPECT_DOUBLE_EQ(window->time(), window->duration());
  press(QKeySequence(Qt::Key_Home));
  EXPECT_DOUBLE_EQ(window->time(), 0.0);
}

TEST_F(GuiViewerWindow, FrameShowsTerrainAndTheRibbonWhereTheTruthProjects) {
  const auto window = open({runDir()});
  TrajectoryView& view = window->view();
  const RunData& run = window->runs().front();
  const double now = 6.0;
  window->seek(now);
  const QImage image = view.grabFramebuffer();
  ASSERT_EQ(image.width(), kWidth);
  ASSERT_EQ(image.height(), kHeight);
  EXPECT_TRUE(view.terrainError().empty()) << view.terrainError();
  image.save(
      QString::fromStdString((fs::path(::testing::TempDir()) / "nadir_viewer_frame.png").string()));

  // Not blank: the terrain's imagery gives many colours, not the clear colour alone.
  std::set<QRgb> colours;
  for (int v = 0; v < kHeight; v += 4) {
    for (int u = 0; u < kWidth; u += 4) colours.insert(image.pixel(u, v));
  }
  EXPECT_GT(colours.size(), 200u);

  const OrbitCamera camera = view.frameCamera();
  int checked = 0;
  for (double t = 0.0; t < now - 0.5; t += 0.25) {
    const auto uv = projectToPixel(camera, kWidth, kHeight, truthAt(run, t));
    ASSERT_TRUE(uv) << t;
    if (!image.valid(static_cast<int>(uv->x()), static_cast<int>(uv->y()))) continue;
    ++checked;
    EXPECT_TRUE(near(image, *uv, 2, isRed)) << "t " << t << " at " << uv->transpose();
  }
  EXPECT_GT(checked, 10);
  // Drawn only up to the playback time.
  for (double t = now + 1.0; t <= window->duration(); t += 0.5) {
    const auto uv = projectToPixel(camera, kWidth, kHeight, truthAt(run, t));
    ASSERT_TRUE(uv);
    EXPECT_FALSE(near(image, *uv, 1, isRed)) << "t " << t;
  }
  // The vehicle marker is centred on the truth now.
  const auto vehicle_uv = projectToPixel(camera, kWidth, kHeight, truthAt(run, now));
  ASSERT_TRUE(vehicle_uv);
  EXPECT_TRUE(near(image, *vehicle_uv, 0, isYellow));
}

TEST_F(GuiViewerWindow, FollowKeepsTheVehicleInTheCentre) {
  const auto window = open({runDir()});
  TrajectoryView& view = window->view();
  view.setFollow(true);
  for (double t : {2.0, 8.0}) {
    window->seek(t);
    const auto vehicle = view.vehiclePosition();
    ASSERT_TRUE(vehicle);
    const auto uv = projectToPixel(view.frameCamera(), kWidth, kHeight, *vehicle);
    ASSERT_TRUE(uv);
    EXPECT_NEAR(uv->x(), (kWidth - 1) / 2.0, 1e-6);
    EXPECT_NEAR(uv->y(), (kHeight - 1) / 2.0, 1e-6);
    const QImage image = view.grabFramebuffer();
    EXPECT_TRUE(near(image, *uv, 0, isYellow));
  }
}

// The vehicle is drawn pointing where the truth heads: yellow ahead of its
// position on screen, not behind it.
TEST_F(GuiViewerWindow, VehiclePointsAlongItsHeading) {
  const auto window = open({runDir()});
  TrajectoryView& view = window->view();
  view.setFollow(true);
  const RunData& run = window->runs().front();
  for (double t : {2.0, 8.0}) {
    window->seek(t);
    const Eigen::Vector3d p = truthAt(run, t);
    // Heading from the truth's track here, independent of its attitude samples.
    const Eigen::Vector3d ahead = truthAt(run, t + 0.2) - p;
    const auto uv = projectToPixel(view.frameCamera(), kWidth, kHeight, p);
    const auto uv_ahead =
        projectToPixel(view.frameCamera(), kWidth, kHeight, p + ahead.normalized());
    ASSERT_TRUE(uv && uv_ahead);
    const Eigen::Vector2d d = (*uv_ahead - *uv).normalized();
    const QImage image = view.grabFramebuffer();
    EXPECT_TRUE(near(image, *uv + 8.0 * d, 0, isYellow)) << t;
    EXPECT_FALSE(near(image, *uv - 8.0 * d, 0, isYellow)) << t;
  }
}

TEST_F(GuiViewerWindow, MouseRotatesPansAndZooms) {
  const auto window = open({runDir()});
  TrajectoryView& view = window->view();
  const OrbitCamera before = view.camera();
  const auto drag = [&](Qt::MouseButton button, QPointF from, QPointF to) {
    QMouseEvent press(QEvent::MouseButtonPress, from, view.mapToGlobal(from), button, button,
                      Qt::NoModifier);
    QApplication::sendEvent(&view, &press);
    QMouseEvent move(QEvent::MouseMove, to, view.mapToGlobal(to), Qt::NoButton, button,
                     Qt::NoModifier);
    QApplication::sendEvent(&view, &move);
  };
  drag(Qt::LeftButton, {100, 100}, {140, 120});
  EXPECT_NE(view.camera().azimuth_rad, before.azimuth_rad);
  EXPECT_GT(view.camera().elevation_rad, before.elevation_rad);
  EXPECT_EQ(view.camera().target, before.target);
  drag(Qt::RightButton, {100, 100}, {150, 100});
  EXPECT_GT((view.camera().target - before.target).norm(), 0.1);
  const QPointF centre(kWidth / 2.0, kHeight / 2.0);
  QWheelEvent wheel(centre, view.mapToGlobal(centre), {}, {0, 120}, Qt::NoButton, Qt::NoModifier,
                    Qt::NoScrollPhase, false);
  QApplication::sendEvent(&view, &wheel);
  EXPECT_LT(view.camera().distance_m, before.distance_m);
}

TEST_F(GuiViewerWindow, SeveralRunsPlayTogether) {
  // A run whose truth lasts 10 s (the synthetic TUM run) and the real run twice.
  const fs::path tum = test::writeTumRun("several");
  fs::copy_file(fs::path(runDir()) / "scenario.yaml", tum / "scenario.yaml");
  const auto window = open({runDir(), tum.string(), runDir()});
  ASSERT_EQ(window->runs().size(), 3u);
  const double expected =
      std::max(window->runs()[0].truth.back().t_s - window->runs()[0].t0_s, 10.0);
  EXPECT_DOUBLE_EQ(window->duration(), expected);

  window->setSpeed(100.0);
  EXPECT_DOUBLE_EQ(window->speed(), 20.0);
  window->setSpeed(0.09);
  EXPECT_DOUBLE_EQ(window->speed(), 0.1);
  window->setSpeed(20.0);
  window->seek(0.0);
  window->setPlaying(true);
  QElapsedTimer clock;
  clock.start();
  while (clock.elapsed() < 200) QApplication::processEvents();
  window->setPlaying(false);
  const double played = window->time();
  const double wall = static_cast<double>(clock.elapsed()) / 1000.0;
  EXPECT_GT(played, 0.0);
  EXPECT_LE(played, 20.0 * wall + 1e-9);
  settle();
  EXPECT_DOUBLE_EQ(window->time(), played);
  // Playing to the end stops there.
  window->seek(window->duration() - 0.05);
  window->setPlaying(true);
  clock.restart();
  while (window->playing() && clock.elapsed() < 2000) QApplication::processEvents();
  EXPECT_FALSE(window->playing());
  EXPECT_DOUBLE_EQ(window->time(), window->duration());

  // Every run's truth is drawn: the TUM run's line at t = 5 s (in a darker red).
  window->seek(9.0);
  const QImage image = window->view().grabFramebuffer();
  const auto uv = projectToPixel(window->view().frameCamera(), kWidth, kHeight,
                                 test::truthPosition(test::kT0 + 5.0));
  ASSERT_TRUE(uv);
  const QColor second = truthColor(1);
  EXPECT_TRUE(near(image, *uv, 2, [&](QRgb c) { return QColor(c) == second; })) << uv->transpose();
}

// The camera image beside the view is the run's newest image at the playback
// time, found here by reading the log without the viewer's code.
TEST_F(GuiViewerWindow, CameraPanelShowsTheLogImageOfTheTime) {
  const auto window = open({runDir()});
  const RunData& run = window->runs().front();
  for (double t : {0.5, 3.3, 7.01}) {
    window->seek(t);
    nadir::image_t expected;
    bool found = false;
    int number = -1;
    core::LcmLogReader reader((fs::path(runDir()) / "run.lcmlog").string());
    int images = 0;
    while (const auto event = reader.next()) {
      if (event->channel != "CAMERA_DOWN") continue;
      nadir::image_t message;
      ASSERT_TRUE(::nadir::test::decodeMessage(event->data.data(), event->data.size(), message));
      if (static_cast<double>(message.utime) / 1e6 <= run.t0_s + t) {
        expected = message;
        found = true;
        number = images;
      }
      ++images;
    }
    ASSERT_TRUE(found) << t;
    const QImage& shown = window->cameraImage();
    ASSERT_EQ(shown.width(), expected.width);
    ASSERT_EQ(shown.height(), expected.height);
    ASSERT_EQ(expected.pixelformat, nadir::image_t::PIXEL_FORMAT_GRAY);
    int differing = 0;
    for (int v = 0; v < expected.height; v += 7) {
      for (int u = 0; u < expected.width; u += 7) {
        const int value = expected.data[static_cast<std::size_t>(v * expected.row_stride + u)];
        if (qGray(shown.pixel(u, v)) != value) ++differing;
      }
    }
    EXPECT_EQ(differing, 0) << t;
    EXPECT_TRUE(window->cameraCaption().contains(QStringLiteral("image %1 at").arg(number)))
        << window->cameraCaption().toStdString();
  }
}

// The camera panel shows the chosen run's images: a run read from TUM files has
// none, and says so.
TEST_F(GuiViewerWindow, CameraPanelShowsTheChosenRun) {
  const fs::path tum = test::writeTumRun("camera_choice");
  const auto window = open({runDir(), tum.string()});
  window->seek(2.0);
  EXPECT_FALSE(window->cameraImage().isNull());
  window->showCameraOf(tum.string());
  EXPECT_TRUE(window->cameraImage().isNull());
  EXPECT_TRUE(window->cameraCaption().contains(QStringLiteral("has no log")))
      << window->cameraCaption().toStdString();
  window->showCameraOf(runDir());
  EXPECT_FALSE(window->cameraImage().isNull());
  window->setCameraChannel("CAMERA_NONE");
  EXPECT_TRUE(window->cameraImage().isNull());
  EXPECT_EQ(window->cameraCaption(), QStringLiteral("no images on run.lcmlog CAMERA_NONE"));
}

// Live mode: the run grows as messages come on the bus, playback stays at the
// newest truth until the user plays, and the newest image is shown.
TEST_F(GuiViewerWindow, LiveModeFollowsTheBus) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  LiveFeed feed(*bus);
  ViewerWindow window({}, std::nullopt);
  window.show();
  window.attachLive(feed, QStringLiteral("live"), 0);
  EXPECT_TRUE(window.runs().empty());
  EXPECT_DOUBLE_EQ(window.duration(), 0.0);

  const auto publish = [&](int k_begin, int k_end) {
    for (int k = k_begin; k < k_end; ++k) {
      const double t = test::truthStamp(k);
      nadir::pose_t pose{};
      pose.utime = static_cast<std::int64_t>(std::llround(t * 1e6));
      const Eigen::Vector3d p = test::truthPosition(t);
      for (int i = 0; i < 3; ++i) pose.pos[i] = p[i];
      pose.orientation[0] = 1.0;
      ::nadir::test::publish(*bus, "POSE_TRUTH", pose);
      if (k % 5 == 0) {
        nadir::image_t image{};
        image.utime = pose.utime;
        image.width = 16;
        image.height = 12;
        image.row_stride = 16;
        image.pixelformat = nadir::image_t::PIXEL_FORMAT_GRAY;
        image.data.assign(16 * 12, static_cast<std::uint8_t>(k));
        image.size = 16 * 12;
        ::nadir::test::publish(*bus, "CAMERA_DOWN", image);
      }
    }
  };
  publish(0, 31);  // 3 s of truth
  window.pollLive();
  ASSERT_EQ(window.runs().size(), 1u);
  EXPECT_EQ(window.runs().front().truth.size(), 31u);
  EXPECT_NEAR(window.duration(), 3.0, 1e-6);
  EXPECT_TRUE(window.followingLive());
  EXPECT_NEAR(window.time(), 3.0, 1e-6);
  EXPECT_EQ(window.timeText(), QStringLiteral("3.00 s / 3.00 s"));
  ASSERT_FALSE(window.cameraImage().isNull());
  EXPECT_EQ(window.cameraImage().width(), 16);
  EXPECT_EQ(qGray(window.cameraImage().pixel(5, 5)), 30);
  const auto vehicle = window.view().vehiclePosition();
  ASSERT_TRUE(vehicle);
  EXPECT_LT((*vehicle - test::truthPosition(test::truthStamp(30))).norm(), 1e-6);

  // Later messages extend it and the time follows.
  publish(31, 81);
  window.pollLive();
  EXPECT_EQ(window.runs().front().truth.size(), 81u);
  EXPECT_NEAR(window.time(), 8.0, 1e-6);
  EXPECT_EQ(qGray(window.cameraImage().pixel(5, 5)), 80);

  // Seeking back to look at the past leaves live: new messages do not move it.
  window.setPlaying(true);
  window.setPlaying(false);
  EXPECT_FALSE(window.followingLive());
  window.seek(2.0);
  publish(81, 101);
  window.pollLive();
  EXPECT_NEAR(window.duration(), 10.0, 1e-6);
  EXPECT_DOUBLE_EQ(window.time(), 2.0);
  EXPECT_EQ(qGray(window.cameraImage().pixel(5, 5)), 20);

  // A flight that starts again (the truth's time goes back) replaces the old one.
  window.setPlaying(false);
  publish(0, 11);
  window.pollLive();
  ASSERT_EQ(window.runs().size(), 1u);
  EXPECT_EQ(window.runs().front().truth.size(), 11u);
  EXPECT_NEAR(window.duration(), 1.0, 1e-6);
}

// Live mode's Reset VO button: a RESET to every VO node at the newest truth
// pose (the truth is live); its menu lists each source seen and resets one.
TEST_F(GuiViewerWindow, LiveResetButtonSendsTheNewestTruth) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  LiveFeed feed(*bus);
  VoResetSender sender(*bus, "VO_COMMAND");
  ViewerWindow window({}, std::nullopt);
  window.show();
  window.attachLive(feed, QStringLiteral("live"), 0);
  auto* reset = window.findChild<QToolButton*>(QStringLiteral("vo_reset"));
  ASSERT_NE(reset, nullptr);
  EXPECT_FALSE(reset->isVisibleTo(&window));
  window.attachVoReset(sender);
  EXPECT_TRUE(reset->isVisibleTo(&window));

  std::vector<msg::VoCommand> sent;
  const core::Subscription listen = msg::subscribe<msg::VoCommand>(
      *bus, "VO_COMMAND", [&sent](const msg::VoCommand& command) { sent.push_back(command); });
  for (int k = 0; k < 11; ++k) {
    const double t = test::truthStamp(k);
    ::nadir::test::publish(*bus, "POSE_TRUTH",
                           test::poseMessage(t, test::truthPosition(t), test::attitude()));
  }
  nadir::vo_estimate_t estimate{};
  estimate.utime = static_cast<std::int64_t>(std::llround(test::truthStamp(10) * 1e6));
  estimate.source = "vo_feature";
  estimate.status = nadir::vo_estimate_t::STATUS_TRACKING;
  estimate.pose = test::poseMessage(test::truthStamp(10), test::truthPosition(test::truthStamp(10)),
                                    test::attitude());
  ::nadir::test::publish(*bus, "POSE_VO_FEATURE", estimate);
  window.pollLive();

  reset->click();
  bus->handleAvailable();
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_TRUE(sent[0].target.empty());
  ASSERT_TRUE(sent[0].initial_pose.has_value());
  EXPECT_EQ(sent[0].utime, estimate.utime);
  EXPECT_LT((sent[0].initial_pose->p_ned_m - test::truthPosition(test::truthStamp(10))).norm(),
            1e-9);

  // The menu: every node, then each source seen.
  QStringList items;
  QAction* one = nullptr;
  for (QAction* action : reset->menu()->actions()) {
    if (action->isSeparator()) continue;
    items << action->text();
    if (action->text() == QStringLiteral("Reset vo_feature")) one = action;
  }
  EXPECT_EQ(items, (QStringList{QStringLiteral("Reset every VO node"),
                                QStringLiteral("Reset vo_feature")}));
  ASSERT_NE(one, nullptr);
  one->trigger();
  bus->handleAvailable();
  ASSERT_EQ(sent.size(), 2u);
  EXPECT_EQ(sent[1].target, "vo_feature");
  EXPECT_TRUE(sent[1].initial_pose.has_value());
}

// Runs opened from the window are added to the others; the first brings its
// scenario's terrain; a folder that is not a run is refused with nothing lost.
TEST_F(GuiViewerWindow, OpenRunAddsARunAndItsTerrain) {
  ViewerWindow window({}, std::nullopt);
  window.show();
  EXPECT_FALSE(window.view().hasTerrain());
  window.openRun(runDir());
  ASSERT_EQ(window.runs().size(), 1u);
  EXPECT_TRUE(window.view().hasTerrain());
  EXPECT_GT(window.duration(), 5.0);
  EXPECT_TRUE(window.view().vehiclePosition().has_value());
  const fs::path empty = test::freshDir("not_a_run");
  EXPECT_THROW(window.openRun(empty.string()), RunDataError);
  EXPECT_EQ(window.runs().size(), 1u);
  window.openRun((fs::path(runDir()) / "run.lcmlog").string());
  EXPECT_EQ(window.runs().size(), 2u);
}

int countOf(const QString& text, const QString& part) { return static_cast<int>(text.count(part)); }

// A run over another world (the fixture's scenario with another procedural seed)
// is marked in the legend; View > Terrain draws any run's terrain, or none.
TEST_F(GuiViewerWindow, TerrainOfAnyRunAndRunsOverAnotherWorldMarked) {
  const auto window = open({runDir()});
  const QString note = "over another world";
  EXPECT_EQ(countOf(window->legendText(), note), 0);

  const fs::path other = test::freshDir("other_world");
  fs::copy_file(fs::path(runDir()) / "truth.tum", other / "truth.tum");
  std::ifstream in(fs::path(runDir()) / "scenario.yaml");
  std::string yaml((std::istreambuf_iterator<char>(in)), {});
  const std::size_t seed = yaml.find("    seed: 1  # world seed");
  ASSERT_NE(seed, std::string::npos);
  yaml.replace(seed, 11, "    seed: 2");
  std::ofstream(other / "scenario.yaml") << yaml;
  window->openRun(other.string());
  EXPECT_NE(window->worldOfRun(other.string()), window->worldOfRun(runDir()));
  EXPECT_EQ(countOf(window->legendText(), note), 1);
  EXPECT_LT(window->legendText().indexOf("other_world"), window->legendText().indexOf(note));

  ASSERT_TRUE(window->showTerrainOf(other.string()));
  ASSERT_NE(window->view().terrain(), nullptr);
  EXPECT_EQ(window->view().terrain()->scenario_path, (other / "scenario.yaml").string());
  EXPECT_EQ(countOf(window->legendText(), note), 1);  // now the fixture's run
  EXPECT_LT(window->legendText().indexOf(note), window->legendText().indexOf("other_world"));

  // A folder without scenario.yaml has no terrain to give: the one drawn stays.
  EXPECT_FALSE(window->showTerrainOf(test::freshDir("no_scenario").string()));
  EXPECT_EQ(window->view().terrain()->scenario_path, (other / "scenario.yaml").string());

  ASSERT_TRUE(window->showTerrainOf({}));
  EXPECT_FALSE(window->view().hasTerrain());
  EXPECT_EQ(countOf(window->legendText(), note), 0);
}

}  // namespace
}  // namespace nadir::gui
