#include "logs/channel_filter.h"

#include <regex.h>

#include <stdexcept>

namespace nadir::logs {

struct ChannelRegex::Compiled {
  regex_t regex{};
  bool compiled = false;
  Compiled() = default;
  Compiled(const Compiled&) = delete;
  Compiled& operator=(const Compiled&) = delete;
  ~Compiled() {
    if (compiled) regfree(&regex);
  }
};

ChannelRegex::ChannelRegex(const std::string& pattern)
    : pattern_(pattern), compiled_(std::make_unique<Compiled>()) {
  const std::string anchored = "^(" + pattern + ")$";
  const int status = regcomp(&compiled_->regex, anchored.c_str(), REG_EXTENDED | REG_NOSUB);
  if (status != 0) {
    char message[256];
    regerror(status, &compiled_->regex, message, sizeof(message));
    throw std::invalid_argument("invalid channel regex '" + pattern + "': " + message);
  }
  compiled_->compiled = true;
}

ChannelRegex::~ChannelRegex() = default;
ChannelRegex::ChannelRegex(ChannelRegex&&) noexcept = default;
ChannelRegex& ChannelRegex::operator=(ChannelRegex&&) noexcept = default;

bool ChannelRegex::matches(const std::string& channel) const {
  return regexec(&compiled_->regex, channel.c_str(), 0, nullptr, 0) == 0;
}

ChannelFilter::ChannelFilter(const std::string& include, const std::string& exclude) {
  if (!include.empty()) include_ = std::make_unique<ChannelRegex>(include);
  if (!exclude.empty()) exclude_ = std::make_unique<ChannelRegex>(exclude);
}

bool ChannelFilter::keeps(const std::string& channel) const {
  if (include_ && !include_->matches(channel)) return false;
  return !(exclude_ && exclude_->matches(channel));
}

}  // namespace nadir::logs
