#pragma once

#include <string>

namespace nadir::cli {

// What `nadir demo` runs today; returns the process exit status.
int runDemo(const std::string& out_dir);

}  // namespace nadir::cli
