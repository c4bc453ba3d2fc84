#pragma once
// Channel selection by regular expression, with LCM's semantics: POSIX
// extended regexes that must match the whole channel name.

#include <memory>
#include <string>

namespace nadir::logs {

// One whole-name channel regex. Throws std::invalid_argument naming the
// pattern if it does not compile.
class ChannelRegex {
 public:
  explicit ChannelRegex(const std::string& pattern);
  ~ChannelRegex();
  ChannelRegex(ChannelRegex&&) noexcept;
  ChannelRegex& operator=(ChannelRegex&&) noexcept;

  bool matches(const std::string& channel) const;
  const std::string& pattern() const { return pattern_; }

 private:
  struct Compiled;
  std::string pattern_;
  std::unique_ptr<Compiled> compiled_;
};

// Keeps channels that match include (empty: every channel) and do not match
// exclude (empty: none).
class ChannelFilter {
 public:
  ChannelFilter(const std::string& include = "", const std::string& exclude = "");

  bool keeps(const std::string& channel) const;

 private:
  std::unique_ptr<ChannelRegex> include_;
  std::unique_ptr<ChannelRegex> exclude_;
};

}  // namespace nadir::logs
