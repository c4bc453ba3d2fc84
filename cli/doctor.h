#pragma once

namespace nadir::cli {

// Probes this machine for what live LCM and headless rendering need, prints
// OK or the exact fix for each, and returns 0 when nothing failed.
int runDoctor();

}  // namespace nadir::cli
