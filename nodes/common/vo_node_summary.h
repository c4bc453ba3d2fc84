#pragma once
// The line a VO node's program prints at exit (its heartbeat summary): frames,
// mean processing time, dropped images and the resets and commands taken.

#include <sstream>
#include <string>

#include "nodes/common/vo_command.h"

namespace nadir::nodes {

// VoNode: frames(), processingSeconds(), droppedImages(), firstDropReason(), commands().
template <class VoNode>
std::string voNodeSummary(const VoNode& node) {
  std::ostringstream out;
  out << node.frames() << " frames, "
      << (node.frames() ? 1000.0 * node.processingSeconds() / node.frames() : 0.0)
      << " ms per frame";
  if (node.droppedImages() > 0)
    out << "; dropped " << node.droppedImages() << " images, the first: " << node.firstDropReason();
  const VoCommandListener& commands = node.commands();
  if (commands.resetsReceived() > 0) out << "; " << commands.resetsReceived() << " resets";
  if (commands.droppedCommands() > 0) {
    out << "; dropped " << commands.droppedCommands()
        << " commands, the first: " << commands.firstDropReason();
  }
  return out.str();
}

}  // namespace nadir::nodes
