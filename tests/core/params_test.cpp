#include "core/params.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace nadir::core {
namespace {

struct CameraParams {
  int width = 640;
  double fps = 30.0;
  bool enabled = true;
  std::string model = "pinhole";
  std::vector<double> distortion = {0.0, 0.0, 0.0, 0.0};
  std::int64_t serial = 0;

  void visit(ParamVisitor& v) {
    v.field("width", &width, {.doc = "image width, pixels", .min = 1, .max = 10000});
    v.field("fps", &fps, {.doc = "frame rate, Hz", .min = 0.1, .max = 2000});
    v.field("enabled", &enabled, {.doc = "publish images"});
    v.field("model", &model, {.doc = "lens model", .choices = {"pinhole", "fisheye"}});
    v.field("distortion", &distortion, {.doc = "k1 k2 p1 p2", .list_size = 4});
    v.field("serial", &serial, {.doc = "camera serial number"});
  }
};

struct VehicleParams {
  std::string name = "rover";
  double max_speed = 2.0;
  CameraParams camera;

  void visit(ParamVisitor& v) {
    v.field("name", &name, {.doc = "vehicle name"});
    v.field("max_speed", &max_speed, {.doc = "speed limit, m/s", .min = 0, .max = 50});
    visitGroup(v, "camera", "front camera", camera);
  }
};

VisitParams visitorOf(VehicleParams& params) {
  return [&params](ParamVisitor& v) { params.visit(v); };
}

// Applies YAML text (source "test.yaml") to params.
void applyText(VehicleParams& params, const std::string& yaml) {
  applyYamlText(yaml, "test.yaml", visitorOf(params));
}

// The message of the ParamError f throws; a test failure if it throws none.
template <class F>
std::string paramErrorOf(F&& f) {
  try {
    f();
  } catch (const ParamError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ParamError";
  return "";
}

::testing::AssertionResult contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

::testing::AssertionResult startsWith(const std::string& text, const std::string& prefix) {
  if (text.starts_with(prefix)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not start with '" << prefix << "'";
}

// Writes text to a fixed file name under the test temporary directory.
std::string writeTempFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream out(path, std::ios::trunc);
  out << text;
  out.close();
  EXPECT_TRUE(out) << "cannot write " << path;
  return path;
}

void expectDefaultCamera(const CameraParams& camera) {
  const CameraParams defaults;
  EXPECT_EQ(camera.width, defaults.width);
  EXPECT_EQ(camera.fps, defaults.fps);
  EXPECT_EQ(camera.enabled, defaults.enabled);
  EXPECT_EQ(camera.model, defaults.model);
  EXPECT_EQ(camera.distortion, defaults.distortion);
  EXPECT_EQ(camera.serial, defaults.serial);
}

// Keys the YAML leaves out keep their defaults, in the group and at the top level.
TEST(ParamsYaml, OmittedKeysKeepDefaults) {
  VehicleParams params;
  applyText(params, "camera:\n  fps: 60\n");
  EXPECT_EQ(params.camera.fps, 60.0);
  EXPECT_EQ(params.name, "rover");
  EXPECT_EQ(params.max_speed, 2.0);
  EXPECT_EQ(params.camera.width, 640);
  EXPECT_TRUE(params.camera.enabled);
  EXPECT_EQ(params.camera.model, "pinhole");
  EXPECT_EQ(params.camera.distortion, std::vector<double>({0.0, 0.0, 0.0, 0.0}));
  EXPECT_EQ(params.camera.serial, 0);
}

// An empty document, a comment-only document and an empty group set nothing.
TEST(ParamsYaml, EmptyDocumentSetsNothing) {
  for (const std::string yaml : {"", "\n", "# nothing here\n", "---\n", "camera: {}\n"}) {
    SCOPED_TRACE("yaml: '" + yaml + "'");
    VehicleParams params;
    EXPECT_NO_THROW(applyText(params, yaml));
    EXPECT_EQ(params.name, "rover");
    EXPECT_EQ(params.max_speed, 2.0);
    expectDefaultCamera(params.camera);
  }
}

// A YAML file sets top-level values, the nested group, the list and the int64 field.
TEST(ParamsYaml, FileValuesAreApplied) {
  const std::string path = writeTempFile("nadir_params_test_values.yaml",
                                         "# vehicle parameters\n"
                                         "name: scout\n"
                                         "max_speed: 3.5\n"
                                         "camera:\n"
                                         "  width: 1280\n"
                                         "  fps: 59.94\n"
                                         "  enabled: false\n"
                                         "  model: fisheye\n"
                                         "  distortion: [-0.2834, 0.0739, 0.0001932, -1.76e-05]\n"
                                         "  serial: 12345678901234\n");
  const auto params = loadParams<VehicleParams>(path);
  EXPECT_EQ(params.name, "scout");
  EXPECT_EQ(params.max_speed, 3.5);
  EXPECT_EQ(params.camera.width, 1280);
  EXPECT_EQ(params.camera.fps, 59.94);
  EXPECT_FALSE(params.camera.enabled);
  EXPECT_EQ(params.camera.model, "fisheye");
  EXPECT_EQ(params.camera.distortion, std::vector<double>({-0.2834, 0.0739, 0.0001932, -1.76e-05}));
  EXPECT_EQ(params.camera.serial, 12345678901234);
}

// An unknown nested key names the dotted key, the file and the key's line.
TEST(ParamsYaml, UnknownNestedKeyNamesKeyFileAndLine) {
  const std::string path = writeTempFile("nadir_params_test_unknown.yaml",
                                         "name: scout\n"   // line 1
                                         "camera:\n"       // line 2
                                         "  width: 800\n"  // line 3
                                         "  fsp: 60\n");   // line 4
  const std::string message = paramErrorOf([&] { loadParams<VehicleParams>(path); });
  EXPECT_TRUE(startsWith(message, path + ":4: camera.fsp: ")) << message;
  EXPECT_TRUE(contains(message, "unknown key"));
}

// An unknown top-level key names the key and its line.
TEST(ParamsYaml, UnknownTopLevelKeyNamesKeyAndLine) {
  VehicleParams params;
  const std::string message = paramErrorOf([&] { applyText(params, "name: a\n\nmax_sped: 3\n"); });
  EXPECT_TRUE(startsWith(message, "test.yaml:3: max_sped: ")) << message;
}

// An out-of-range value names the key, the file, the line and the range.
TEST(ParamsYaml, OutOfRangeNamesKeyFileAndRange) {
  const std::string path = writeTempFile("nadir_params_test_range.yaml",
                                         "camera:\n"        // line 1
                                         "  width: 640\n"   // line 2
                                         "  fps: 2500\n");  // line 3
  const std::string message = paramErrorOf([&] { loadParams<VehicleParams>(path); });
  EXPECT_TRUE(startsWith(message, path + ":3: camera.fps: ")) << message;
  EXPECT_TRUE(contains(message, "2500"));
  EXPECT_TRUE(contains(message, "[0.1, 2000]"));
}

// Values just outside either bound are rejected, for int and double fields.
TEST(ParamsYaml, JustOutsideBoundsIsRejected) {
  for (const std::string yaml :
       {"camera: {width: 0}", "camera: {width: 10001}", "camera: {fps: 0.09}",
        "camera: {fps: 2000.5}", "max_speed: -0.001", "camera: {width: -5}"}) {
    SCOPED_TRACE(yaml);
    VehicleParams params;
    const std::string message = paramErrorOf([&] { applyText(params, yaml); });
    EXPECT_TRUE(contains(message, "out of range"));
  }
  VehicleParams params;
  EXPECT_TRUE(
      contains(paramErrorOf([&] { applyText(params, "camera: {width: 0}"); }), "[1, 10000]"));
}

// Values exactly at a bound are accepted: the range is inclusive.
TEST(ParamsYaml, ValueAtBoundIsAccepted) {
  VehicleParams params;
  applyText(params, "camera:\n  width: 1\n  fps: 0.1\nmax_speed: 0\n");
  EXPECT_EQ(params.camera.width, 1);
  EXPECT_EQ(params.camera.fps, 0.1);
  EXPECT_EQ(params.max_speed, 0.0);
  applyText(params, "camera:\n  width: 10000\n  fps: 2000\nmax_speed: 50\n");
  EXPECT_EQ(params.camera.width, 10000);
  EXPECT_EQ(params.camera.fps, 2000.0);
  EXPECT_EQ(params.max_speed, 50.0);
}

// A string, a fraction or a map where an int is wanted is rejected naming the key.
TEST(ParamsYaml, WrongTypeForIntNamesKey) {
  for (const std::string yaml :
       {"camera:\n  width: wide\n", "camera:\n  width: 2.5\n", "camera:\n  width: {a: 1}\n",
        "camera:\n  width: [1, 2]\n", "camera:\n  width: 99999999999\n"}) {
    SCOPED_TRACE(yaml);
    VehicleParams params;
    const std::string message = paramErrorOf([&] { applyText(params, yaml); });
    EXPECT_TRUE(startsWith(message, "test.yaml:2: camera.width: ")) << message;
    EXPECT_TRUE(contains(message, "expected an integer"));
    EXPECT_EQ(params.camera.width, 640);
  }
}

// Maps and lists where a scalar is wanted, and other mismatches, are rejected naming the key.
TEST(ParamsYaml, WrongTypeForOtherFieldsNamesKey) {
  struct Case {
    std::string yaml;
    std::string key;
  };
  for (const Case& c : std::vector<Case>{
           {"name: {first: a}\n", "name"},
           {"name: [a, b]\n", "name"},
           {"max_speed: fast\n", "max_speed"},
           {"max_speed: {x: 1}\n", "max_speed"},
           {"camera:\n  enabled: maybe\n", "camera.enabled"},
           {"camera:\n  enabled: {x: 1}\n", "camera.enabled"},
           {"camera:\n  serial: 1.5\n", "camera.serial"},
           {"camera:\n  distortion: 0.1\n", "camera.distortion"},
           {"camera:\n  distortion: [a, b, c, d]\n", "camera.distortion"},
           {"camera:\n  fps:\n", "camera.fps"},
       }) {
    SCOPED_TRACE(c.yaml);
    VehicleParams params;
    const std::string message = paramErrorOf([&] { applyText(params, c.yaml); });
    EXPECT_TRUE(contains(message, ": " + c.key + ": ")) << message;
  }
}

// A scalar where a group is wanted is rejected naming the group.
TEST(ParamsYaml, ScalarForGroupIsRejected) {
  VehicleParams params;
  const std::string message = paramErrorOf([&] { applyText(params, "camera: 3\n"); });
  EXPECT_TRUE(startsWith(message, "test.yaml:1: camera: ")) << message;
  EXPECT_TRUE(contains(message, "expected a map"));
}

// A top level that is not a map is rejected.
TEST(ParamsYaml, NonMapTopLevelIsRejected) {
  VehicleParams params;
  EXPECT_TRUE(contains(paramErrorOf([&] { applyText(params, "- 1\n- 2\n"); }), "test.yaml"));
  EXPECT_TRUE(contains(paramErrorOf([&] { applyText(params, "just text\n"); }), "test.yaml"));
}

// A string among the choices is accepted; one outside them is rejected listing the choices.
TEST(ParamsYaml, StringChoices) {
  VehicleParams params;
  applyText(params, "camera:\n  model: fisheye\n");
  EXPECT_EQ(params.camera.model, "fisheye");
  const std::string message =
      paramErrorOf([&] { applyText(params, "camera:\n  model: orthographic\n"); });
  EXPECT_TRUE(startsWith(message, "test.yaml:2: camera.model: ")) << message;
  EXPECT_TRUE(contains(message, "orthographic"));
  EXPECT_TRUE(contains(message, "pinhole, fisheye"));
  EXPECT_EQ(params.camera.model, "fisheye");
}

// A string field without choices takes any text, including one that looks like a number.
TEST(ParamsYaml, FreeStringTakesAnyScalar) {
  VehicleParams params;
  applyText(params, "name: \"42\"\n");
  EXPECT_EQ(params.name, "42");
  applyText(params, "name: 'rover: one # two'\n");
  EXPECT_EQ(params.name, "rover: one # two");
}

// A list of the wrong length is rejected naming the key and both lengths.
TEST(ParamsYaml, ListOfWrongLengthIsRejected) {
  for (const std::string yaml :
       {"camera:\n  distortion: [0.1, 0.2, 0.3]\n",
        "camera:\n  distortion: [0.1, 0.2, 0.3, 0.4, 0.5]\n", "camera:\n  distortion: []\n"}) {
    SCOPED_TRACE(yaml);
    VehicleParams params;
    const std::string message = paramErrorOf([&] { applyText(params, yaml); });
    EXPECT_TRUE(startsWith(message, "test.yaml:2: camera.distortion: ")) << message;
    EXPECT_TRUE(contains(message, "list of 4"));
  }
}

// NaN and infinities are rejected for a double and for the elements of a list.
TEST(ParamsYaml, NonFiniteNumbersAreRejected) {
  for (const std::string yaml :
       {"camera:\n  fps: .nan\n", "camera:\n  fps: .inf\n", "camera:\n  fps: -.inf\n",
        "max_speed: .NaN\n", "camera:\n  distortion: [0, .nan, 0, 0]\n",
        "camera:\n  distortion: [0, 0, 0, .inf]\n"}) {
    SCOPED_TRACE(yaml);
    VehicleParams params;
    const std::string message = paramErrorOf([&] { applyText(params, yaml); });
    EXPECT_TRUE(contains(message, "finite")) << message;
    EXPECT_TRUE(std::isfinite(params.camera.fps));
    EXPECT_EQ(params.camera.distortion, std::vector<double>({0.0, 0.0, 0.0, 0.0}));
  }
}

// A rejected value leaves that field at its previous value and keeps earlier applied values.
TEST(ParamsYaml, RejectedValueLeavesFieldUnchanged) {
  VehicleParams params;
  applyText(params,
            "name: scout\ncamera:\n  fps: 60\n  model: fisheye\n"
            "  distortion: [0.1, 0.2, 0.3, 0.4]\n  width: 800\n");
  const std::vector<double> distortion = {0.1, 0.2, 0.3, 0.4};

  EXPECT_THROW(applyText(params, "camera:\n  fps: 5000\n"), ParamError);
  EXPECT_EQ(params.camera.fps, 60.0);
  EXPECT_THROW(applyText(params, "camera:\n  fps: .nan\n"), ParamError);
  EXPECT_EQ(params.camera.fps, 60.0);
  EXPECT_THROW(applyText(params, "camera:\n  width: 2.5\n"), ParamError);
  EXPECT_EQ(params.camera.width, 800);
  EXPECT_THROW(applyText(params, "camera:\n  model: orthographic\n"), ParamError);
  EXPECT_EQ(params.camera.model, "fisheye");
  EXPECT_THROW(applyText(params, "camera:\n  distortion: [9, 9, 9]\n"), ParamError);
  EXPECT_EQ(params.camera.distortion, distortion);
  EXPECT_THROW(applyText(params, "camera:\n  distortion: [9, 9, 9, .inf]\n"), ParamError);
  EXPECT_EQ(params.camera.distortion, distortion);
  EXPECT_THROW(applyAssignment("camera.fps=abc", "--set", visitorOf(params)), ParamError);
  EXPECT_EQ(params.camera.fps, 60.0);

  EXPECT_EQ(params.name, "scout");
  EXPECT_EQ(params.camera.width, 800);
  EXPECT_EQ(params.camera.model, "fisheye");
  EXPECT_EQ(params.camera.distortion, distortion);
}

// A missing file is a ParamError naming the path.
TEST(ParamsYaml, MissingFileNamesPath) {
  const std::string path = ::testing::TempDir() + "nadir_params_test_missing.yaml";
  std::filesystem::remove(path);
  const std::string message = paramErrorOf([&] { loadParams<VehicleParams>(path); });
  EXPECT_TRUE(startsWith(message, path + ": ")) << message;
}

// Invalid YAML in a file is a ParamError naming the file and the line of the error.
TEST(ParamsYaml, InvalidYamlNamesFileAndLine) {
  const std::string path = writeTempFile("nadir_params_test_invalid.yaml",
                                         "name: scout\n"          // line 1
                                         "camera:\n"              // line 2
                                         "  width: 800: 600\n");  // line 3: a second ':'
  const std::string message = paramErrorOf([&] { loadParams<VehicleParams>(path); });
  EXPECT_TRUE(startsWith(message, path + ":3: ")) << message;
  EXPECT_TRUE(contains(message, "not valid YAML"));
}

// Invalid YAML text is a ParamError naming the source and the line of the error.
TEST(ParamsYaml, InvalidYamlTextNamesSourceAndLine) {
  VehicleParams params;
  const std::string message =
      paramErrorOf([&] { applyText(params, "name: scout\nmax_speed: [1, 2\n"); });
  EXPECT_TRUE(startsWith(message, "test.yaml:")) << message;
  EXPECT_TRUE(contains(message, "not valid YAML"));
}

// "camera.fps=60" sets the nested value and leaves the rest alone.
TEST(ParamsAssignment, SetsNestedValue) {
  VehicleParams params;
  applyAssignment("camera.fps=60", "--set", visitorOf(params));
  EXPECT_EQ(params.camera.fps, 60.0);
  EXPECT_EQ(params.camera.width, 640);
  EXPECT_EQ(params.name, "rover");
}

// Top-level values, booleans, strings and int64 take YAML syntax.
TEST(ParamsAssignment, SetsValuesOfEveryType) {
  VehicleParams params;
  applyAssignments(params,
                   {"name=scout", "max_speed=4.5", "camera.enabled=false", "camera.model=fisheye",
                    "camera.width=1920", "camera.serial=9000000000"});
  EXPECT_EQ(params.name, "scout");
  EXPECT_EQ(params.max_speed, 4.5);
  EXPECT_FALSE(params.camera.enabled);
  EXPECT_EQ(params.camera.model, "fisheye");
  EXPECT_EQ(params.camera.width, 1920);
  EXPECT_EQ(params.camera.serial, 9000000000);
}

// A list value in flow syntax sets the list field.
TEST(ParamsAssignment, SetsList) {
  VehicleParams params;
  applyAssignment("camera.distortion=[0.1, 0.2, 0.3, 0.4]", "--set", visitorOf(params));
  EXPECT_EQ(params.camera.distortion, std::vector<double>({0.1, 0.2, 0.3, 0.4}));
}

// A misspelt nested key is rejected naming the dotted key and the assignment.
TEST(ParamsAssignment, UnknownKeyIsRejected) {
  VehicleParams params;
  const std::string message =
      paramErrorOf([&] { applyAssignment("camera.fsp=1", "--set", visitorOf(params)); });
  EXPECT_TRUE(contains(message, "camera.fsp: ")) << message;
  EXPECT_TRUE(contains(message, "--set camera.fsp=1"));
  EXPECT_TRUE(contains(message, "unknown key"));
  EXPECT_TRUE(
      contains(paramErrorOf([&] { applyAssignment("colour=red", "--set", visitorOf(params)); }),
               "colour: "));
}

// Assignments without '=' or with an empty key or key part are rejected.
TEST(ParamsAssignment, MalformedAssignmentIsRejected) {
  VehicleParams params;
  EXPECT_TRUE(
      contains(paramErrorOf([&] { applyAssignment("noequals", "--set", visitorOf(params)); }),
               "expected key=value"));
  EXPECT_THROW(applyAssignment("=3", "--set", visitorOf(params)), ParamError);
  EXPECT_THROW(applyAssignment("camera..fps=3", "--set", visitorOf(params)), ParamError);
  EXPECT_THROW(applyAssignment("camera.fps.=3", "--set", visitorOf(params)), ParamError);
  EXPECT_THROW(applyAssignment("camera.fps=[1, 2", "--set", visitorOf(params)), ParamError);
  EXPECT_EQ(params.camera.fps, 30.0);
}

// A group given a scalar ("camera=3") is rejected naming the group.
TEST(ParamsAssignment, ScalarForGroupIsRejected) {
  VehicleParams params;
  const std::string message =
      paramErrorOf([&] { applyAssignment("camera=3", "--set", visitorOf(params)); });
  EXPECT_TRUE(contains(message, "camera: ")) << message;
  EXPECT_TRUE(contains(message, "expected a map"));
  expectDefaultCamera(params.camera);
}

// Assignments are checked like YAML: out of range, wrong type and empty values are rejected.
TEST(ParamsAssignment, ValuesAreValidated) {
  VehicleParams params;
  EXPECT_TRUE(
      contains(paramErrorOf([&] { applyAssignments(params, {"camera.fps=0"}); }), "camera.fps: "));
  EXPECT_TRUE(contains(paramErrorOf([&] { applyAssignments(params, {"camera.width=2.5"}); }),
                       "camera.width: "));
  EXPECT_TRUE(
      contains(paramErrorOf([&] { applyAssignments(params, {"camera.fps="}); }), "camera.fps: "));
  EXPECT_TRUE(
      contains(paramErrorOf([&] { applyAssignments(params, {"camera.distortion=[1, 2]"}); }),
               "camera.distortion: "));
  expectDefaultCamera(params.camera);
}

// Current values pass validation; a value set out of range in code is caught, naming the key.
TEST(ParamsValidate, CatchesValuesSetInCode) {
  VehicleParams params;
  EXPECT_NO_THROW(validateParams(visitorOf(params), "defaults"));

  params.camera.fps = 5000;
  std::string message = paramErrorOf([&] { validateParams(visitorOf(params), "code"); });
  EXPECT_TRUE(startsWith(message, "code: camera.fps: ")) << message;
  EXPECT_TRUE(contains(message, "[0.1, 2000]"));

  params.camera.fps = 30;
  params.camera.model = "bogus";
  EXPECT_TRUE(startsWith(paramErrorOf([&] { validateParams(visitorOf(params), "code"); }),
                         "code: camera.model: "));

  params.camera.model = "pinhole";
  params.camera.distortion = {1.0, 2.0};
  EXPECT_TRUE(startsWith(paramErrorOf([&] { validateParams(visitorOf(params), "code"); }),
                         "code: camera.distortion: "));

  params.camera.distortion = {0, 0, 0, 0};
  params.max_speed = std::nan("");
  EXPECT_TRUE(startsWith(paramErrorOf([&] { validateParams(visitorOf(params), "code"); }),
                         "code: max_speed: "));
}

// The text lists every key with its value and doc, nested keys indented under the group.
TEST(ParamsFormat, ListsKeysValuesAndDocs) {
  VehicleParams params;
  params.camera.distortion = {0.5, -0.25, 0, 1e-05};
  const std::string text = formatParamsOf(params);
  EXPECT_TRUE(startsWith(text, "name: \"rover\"  # vehicle name\n")) << text;
  EXPECT_TRUE(contains(text, "\nmax_speed: 2  # speed limit, m/s\n")) << text;
  EXPECT_TRUE(contains(text, "\ncamera:  # front camera\n")) << text;
  EXPECT_TRUE(contains(text, "\n  width: 640  # image width, pixels\n")) << text;
  EXPECT_TRUE(contains(text, "\n  fps: 30  # frame rate, Hz\n")) << text;
  EXPECT_TRUE(contains(text, "\n  enabled: true  # publish images\n")) << text;
  EXPECT_TRUE(contains(text, "\n  model: \"pinhole\"  # lens model\n")) << text;
  EXPECT_TRUE(contains(text, "\n  distortion: [0.5, -0.25, 0, 1e-05]  # k1 k2 p1 p2\n")) << text;
  EXPECT_TRUE(contains(text, "\n  serial: 0  # camera serial number\n")) << text;
  // The group's fields come after the group line.
  EXPECT_LT(text.find("camera:"), text.find("  width:"));
  EXPECT_EQ(formatParams(visitorOf(params)), text);
}

// Applying the formatted text to defaults reproduces every value.
TEST(ParamsFormat, RoundTripsThroughYaml) {
  VehicleParams original;
  original.name = "scout \"one\": #2";
  original.max_speed = 12.75;
  original.camera.width = 1280;
  original.camera.fps = 59.94;
  original.camera.enabled = false;
  original.camera.model = "fisheye";
  original.camera.distortion = {-0.2834, 0.0739, 0.0001932, -1.76e-05};
  original.camera.serial = -1234567890123;
  const std::string text = formatParamsOf(original);

  VehicleParams copy;
  ASSERT_NO_THROW(applyYamlText(text, "formatted", visitorOf(copy))) << text;
  EXPECT_EQ(copy.name, original.name);
  EXPECT_EQ(copy.max_speed, original.max_speed);
  EXPECT_EQ(copy.camera.width, original.camera.width);
  EXPECT_EQ(copy.camera.fps, original.camera.fps);
  EXPECT_EQ(copy.camera.enabled, original.camera.enabled);
  EXPECT_EQ(copy.camera.model, original.camera.model);
  EXPECT_EQ(copy.camera.distortion, original.camera.distortion);
  EXPECT_EQ(copy.camera.serial, original.camera.serial);
  EXPECT_EQ(formatParamsOf(copy), text);
}

// The formatted defaults re-applied leave the defaults unchanged.
TEST(ParamsFormat, DefaultsRoundTrip) {
  VehicleParams defaults;
  const std::string text = formatParamsOf(defaults);
  VehicleParams copy;
  copy.name = "other";
  copy.camera.width = 1;
  applyYamlText(text, "formatted", visitorOf(copy));
  EXPECT_EQ(copy.name, "rover");
  expectDefaultCamera(copy.camera);
  EXPECT_EQ(formatParamsOf(copy), text);
}

// A double that needs 17 significant digits survives formatting and re-reading exactly.
TEST(ParamsFormat, DoublesRoundTripExactly) {
  VehicleParams original;
  original.max_speed = 1.0 / 3.0;
  original.camera.distortion = {0.1, 1.0 / 7.0, -2.0 / 3.0, 1e-300};
  VehicleParams copy;
  applyYamlText(formatParamsOf(original), "formatted", visitorOf(copy));
  EXPECT_EQ(copy.max_speed, 1.0 / 3.0);
  EXPECT_EQ(copy.camera.distortion, original.camera.distortion);
}

// A key with no value is reported on the key's own line, not where the parser resumes.
TEST(ParamsYaml, EmptyValueNamesTheKeysLine) {
  VehicleParams params;
  EXPECT_TRUE(
      startsWith(paramErrorOf([&] { applyText(params, "name: a\nmax_speed:\n\n\ncamera: {}\n"); }),
                 "test.yaml:2: max_speed: has no value"));
}

// A key given twice is an error naming the second occurrence's line.
TEST(ParamsYaml, DuplicateKeyIsRejected) {
  VehicleParams params;
  EXPECT_TRUE(startsWith(paramErrorOf([&] { applyText(params, "max_speed: 2\nmax_speed: 3\n"); }),
                         "test.yaml:2: max_speed: given twice"));
  EXPECT_TRUE(
      startsWith(paramErrorOf([&] { applyText(params, "camera:\n  fps: 10\n  fps: 20\n"); }),
                 "test.yaml:3: camera.fps: given twice"));
}

// A key that is a list or a map (YAML's "? - x") is an error naming its line
// and the group it is in (found by fuzzing: yaml-cpp's conversion error ended
// the program, fuzz/regressions/scenario).
TEST(ParamsYaml, AKeyThatIsAListIsRejected) {
  VehicleParams params;
  const std::string top = paramErrorOf([&] { applyText(params, "name: a\n? - [0, 600]\n: 1\n"); });
  EXPECT_TRUE(startsWith(top, "test.yaml:2: ")) << top;
  EXPECT_NE(top.find("a key must be a name, not a list or a map"), std::string::npos) << top;
  const std::string inner =
      paramErrorOf([&] { applyText(params, "camera:\n  ? [fps]\n  : 10\n"); });
  EXPECT_TRUE(startsWith(inner, "test.yaml:2: camera: a key must be a name")) << inner;
}

// A document with one bad entry changes no field, including those before the bad one.
TEST(ParamsYaml, BadDocumentChangesNothing) {
  VehicleParams params;
  EXPECT_THROW(applyText(params, "name: changed\ncamera:\n  fps: 60\n  width: -1\n"), ParamError);
  EXPECT_EQ(params.name, "rover");
  EXPECT_EQ(params.camera.fps, 30.0);
  EXPECT_THROW(applyText(params, "name: changed\nmax_speed: 3\nmax_sped: 4\n"), ParamError);
  EXPECT_EQ(params.name, "rover");
  EXPECT_EQ(params.max_speed, 2.0);
}

struct RigParams {
  std::map<std::string, CameraParams> cameras;
  void visit(ParamVisitor& v) { visitGroupMap(v, "cameras", "cameras by name", cameras); }
};

VisitParams visitorOf(RigParams& params) {
  return [&params](ParamVisitor& v) { params.visit(v); };
}

// A map of named groups: entries are created with defaults, then their fields applied.
TEST(ParamsGroupMap, NamedEntriesAreCreatedAndFilled) {
  RigParams rig;
  applyYamlText("cameras:\n  down:\n    fps: 31\n  ppa:\n    width: 256\n", "rig.yaml",
                visitorOf(rig));
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_EQ(rig.cameras.at("down").fps, 31.0);
  EXPECT_EQ(rig.cameras.at("down").width, 640);
  EXPECT_EQ(rig.cameras.at("ppa").width, 256);
  EXPECT_EQ(rig.cameras.at("ppa").fps, 30.0);
  applyAssignment("cameras.ppa.fps=200", "--set", visitorOf(rig));
  EXPECT_EQ(rig.cameras.at("ppa").fps, 200.0);
  applyAssignment("cameras.side.width=100", "--set", visitorOf(rig));
  EXPECT_EQ(rig.cameras.at("side").width, 100);
}

// An error inside one entry names the entry's key path and leaves no new entry behind.
TEST(ParamsGroupMap, ErrorsNameTheEntryAndChangeNothing) {
  RigParams rig;
  EXPECT_TRUE(startsWith(paramErrorOf([&] {
                           applyYamlText("cameras:\n  down:\n    fps: 31\n  ppa:\n    fsp: 2\n",
                                         "rig.yaml", visitorOf(rig));
                         }),
                         "rig.yaml:5: cameras.ppa.fsp: unknown key"));
  EXPECT_TRUE(rig.cameras.empty());
  EXPECT_TRUE(startsWith(paramErrorOf([&] {
                           applyYamlText("cameras:\n  down: {}\n  down: {}\n", "rig.yaml",
                                         visitorOf(rig));
                         }),
                         "rig.yaml:3: cameras.down: given twice"));
  EXPECT_TRUE(rig.cameras.empty());
}

// Formatted named groups read back to the same entries and values.
TEST(ParamsGroupMap, FormatRoundTrip) {
  RigParams rig;
  rig.cameras["down"].fps = 31.0;
  rig.cameras["ppa"].width = 256;
  RigParams copy;
  applyYamlText(formatParamsOf(rig), "formatted", visitorOf(copy));
  ASSERT_EQ(copy.cameras.size(), 2u);
  EXPECT_EQ(copy.cameras.at("down").fps, 31.0);
  EXPECT_EQ(copy.cameras.at("ppa").width, 256);
  EXPECT_EQ(formatParamsOf(copy), formatParamsOf(rig));
}

// An empty map is formatted as {} ahead of its comment and reads back as an empty map.
TEST(ParamsGroupMap, EmptyMapRoundTrips) {
  RigParams rig;
  const std::string text = formatParamsOf(rig);
  EXPECT_EQ(text, "cameras: {}  # cameras by name\n");
  RigParams copy;
  ASSERT_NO_THROW(applyYamlText(text, "formatted", visitorOf(copy))) << text;
  EXPECT_TRUE(copy.cameras.empty());
}

struct RouteParams {
  NumberRows waypoints = {{0.0, 0.0}};
  void visit(ParamVisitor& v) {
    v.field("waypoints", &waypoints,
            {.doc = "north, east[, height]", .min = -1000, .max = 1000, .row_sizes = {2, 3}});
  }
};

// A table of numbers loads row by row; rows of an allowed length may differ in length.
TEST(ParamsRows, TableLoadsAndRoundTrips) {
  RouteParams params;
  const auto visit = [&params](ParamVisitor& v) { params.visit(v); };
  applyYamlText("waypoints: [[1, 2], [3.5, -4, 10]]\n", "route.yaml", visit);
  ASSERT_EQ(params.waypoints.size(), 2u);
  EXPECT_EQ(params.waypoints[0], (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(params.waypoints[1], (std::vector<double>{3.5, -4.0, 10.0}));
  EXPECT_EQ(formatParamsOf(params),
            "waypoints: [[1, 2], [3.5, -4, 10]]  # north, east[, height]\n");
  applyAssignment("waypoints=[[7, 8]]", "--set", visit);
  EXPECT_EQ(params.waypoints, (NumberRows{{7.0, 8.0}}));
}

// A row of the wrong length, a value out of range or a flat list is refused with the row named.
TEST(ParamsRows, BadRowsAreRefusedAndChangeNothing) {
  RouteParams params;
  const auto visit = [&params](ParamVisitor& v) { params.visit(v); };
  std::string message =
      paramErrorOf([&] { applyYamlText("waypoints: [[1, 2], [3]]\n", "route.yaml", visit); });
  EXPECT_TRUE(startsWith(message, "route.yaml:1: waypoints[1]: expected 2 or 3 numbers, got 1"))
      << message;
  message =
      paramErrorOf([&] { applyYamlText("waypoints: [[1, 2], [3, 2000]]\n", "route.yaml", visit); });
  EXPECT_TRUE(contains(message, "waypoints[1]: 2000 is out of range")) << message;
  message = paramErrorOf([&] { applyYamlText("waypoints: [1, 2]\n", "route.yaml", visit); });
  EXPECT_TRUE(contains(message, "expected a list of lists of numbers")) << message;
  EXPECT_EQ(params.waypoints, (NumberRows{{0.0, 0.0}}));
}

}  // namespace
}  // namespace nadir::core
