// A scenario file and --set overrides on any bytes: the input is the file's
// text, then the overrides, each after a NUL byte. A scenario that loads prints
// and loads again from its own printout with the same values.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/params.h"
#include "fuzz/fuzz_input.h"
#include "nodes/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto parts = nadir::fuzz::split(data, size, '\0');
  const std::string path = nadir::fuzz::writeInput(parts.front(), "scenario.yaml");
  const std::vector<std::string> overrides(parts.begin() + 1, parts.end());
  try {
    nadir::nodes::ScenarioParams scenario = nadir::nodes::loadScenario(path, overrides);
    const std::string printed = nadir::core::formatParamsOf(scenario);
    nadir::nodes::ScenarioParams again =
        nadir::nodes::loadScenario(nadir::fuzz::writeInput(printed, "printed.yaml"));
    NADIR_FUZZ_REQUIRE(nadir::core::formatParamsOf(again) == printed);
  } catch (const nadir::core::ParamError&) {
  }
  return 0;
}
