// The sweep file loader on any bytes: a sweep that loads plans its cells, each
// cell's folder is a child of the sweep's folder (no value leads elsewhere),
// and its command sets every override it stands for.
#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include "core/params.h"
#include "fuzz/fuzz_input.h"
#include "run/sweep.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  const std::string path = nadir::fuzz::writeInput(data, size, "sweep.yaml");
  try {
    const nadir::run::SweepSpec spec = nadir::run::loadSweep(path);
    for (const nadir::run::SweepCell& cell : nadir::run::planSweep(spec)) {
      const fs::path folder(cell.out_dir);
      NADIR_FUZZ_REQUIRE(folder.parent_path() == fs::path(spec.out_dir));
      NADIR_FUZZ_REQUIRE(folder.filename() != "." && folder.filename() != "..");
      NADIR_FUZZ_REQUIRE(!nadir::run::cellCommand(spec, cell, "nadir").empty());
    }
  } catch (const nadir::core::ParamError&) {
  }
  return 0;
}
