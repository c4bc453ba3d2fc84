#pragma once

#include <string>
#include <vector>

namespace nadir::cli {

// `nadir snapshot`: renders what a camera sees from one pose over a world and
// writes it as a PNG. Returns the process exit status.
int runSnapshot(const std::string& config_path, const std::vector<std::string>& overrides,
                const std::string& out_path);

}  // namespace nadir::cli
