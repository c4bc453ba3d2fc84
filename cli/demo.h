#pragma once

#include <string>

namespace nadir::cli {

// `nadir demo`: flies the default scenario with nadir run into out_dir and
// prints the results; returns the process exit status.
int runDemo(const std::string& out_dir);

}  // namespace nadir::cli
