#include "core/utc_time.h"

#include <charconv>
#include <cstdio>
#include <stdexcept>

namespace nadir::core {
namespace {

bool isLeap(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

int daysInMonth(int year, int month) {
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return month == 2 && isLeap(year) ? 29 : kDays[month - 1];
}

// Reads exactly `digits` decimal digits at text[at].
int field(std::string_view text, std::size_t at, std::size_t digits, const char* name) {
  int value = 0;
  const bool fits = at + digits <= text.size();
  const char* first = text.data() + (fits ? at : 0);
  const auto [end, error] = std::from_chars(first, first + (fits ? digits : 0), value);
  if (!fits || error != std::errc() || end != first + digits || *first == '-' || *first == '+') {
    throw std::invalid_argument("'" + std::string(text) + "': the " + name +
                                " is not a number of " + std::to_string(digits) +
                                " digits (expected e.g. 2024-06-21T10:00:00Z, in UTC)");
  }
  return value;
}

}  // namespace

// Howard Hinnant's days_from_civil.
std::int64_t daysFromCivil(int year, int month, int day) {
  const std::int64_t y = static_cast<std::int64_t>(year) - (month <= 2 ? 1 : 0);
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;
  const std::int64_t doy = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

void civilFromDays(std::int64_t days, int& year, int& month, int& day) {
  days += 719468;
  const std::int64_t era = (days >= 0 ? days : days - 146096) / 146097;
  const std::int64_t doe = days - era * 146097;
  const std::int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const std::int64_t mp = (5 * doy + 2) / 153;
  day = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  month = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  year = static_cast<int>(yoe + era * 400 + (month <= 2 ? 1 : 0));
}

std::int64_t utimeFromUtc(std::string_view text) {
  const auto expect = [&text](std::size_t at, char c) {
    if (at >= text.size() || text[at] != c) {
      throw std::invalid_argument("'" + std::string(text) + "': expected '" + std::string(1, c) +
                                  "' at character " + std::to_string(at + 1) +
                                  " (a UTC date and time such as 2024-06-21T10:00:00Z)");
    }
  };
  const int year = field(text, 0, 4, "year");
  expect(4, '-');
  const int month = field(text, 5, 2, "month");
  expect(7, '-');
  const int day = field(text, 8, 2, "day");
  expect(10, 'T');
  const int hour = field(text, 11, 2, "hour");
  expect(13, ':');
  const int minute = field(text, 14, 2, "minute");
  expect(16, ':');
  const int second = field(text, 17, 2, "second");
  std::size_t at = 19;
  std::int64_t micros = 0;
  if (at < text.size() && text[at] == '.') {
    ++at;
    std::int64_t scale = 100000;
    const std::size_t first = at;
    while (at < text.size() && text[at] >= '0' && text[at] <= '9') {
      micros += scale * (text[at] - '0');
      scale /= 10;
      ++at;
    }
    if (at == first || at - first > 6) {
      throw std::invalid_argument("'" + std::string(text) +
                                  "': fractional seconds need 1 to 6 digits");
    }
  }
  expect(at, 'Z');
  if (at + 1 != text.size()) {
    throw std::invalid_argument("'" + std::string(text) + "': text after the Z");
  }
  if (year < 1970 || month < 1 || month > 12 || day < 1 || day > daysInMonth(year, month) ||
      hour > 23 || minute > 59 || second > 59) {
    throw std::invalid_argument("'" + std::string(text) +
                                "' is not a date and time (from 1970 on; no leap seconds)");
  }
  const std::int64_t seconds =
      daysFromCivil(year, month, day) * 86400 + hour * 3600 + minute * 60 + second;
  return seconds * 1'000'000 + micros;
}

std::string utcFromUtime(std::int64_t utime) {
  std::int64_t seconds = utime / 1'000'000;
  std::int64_t micros = utime % 1'000'000;
  if (micros < 0) {
    micros += 1'000'000;
    --seconds;
  }
  std::int64_t days = seconds / 86400;
  std::int64_t in_day = seconds % 86400;
  if (in_day < 0) {
    in_day += 86400;
    --days;
  }
  int year = 0, month = 0, day = 0;
  civilFromDays(days, year, month, day);
  char text[40];
  const int hour = static_cast<int>(in_day / 3600);
  const int minute = static_cast<int>(in_day / 60 % 60);
  const int second = static_cast<int>(in_day % 60);
  if (micros == 0) {
    std::snprintf(text, sizeof(text), "%04d-%02d-%02dT%02d:%02d:%02dZ", year, month, day, hour,
                  minute, second);
  } else {
    std::snprintf(text, sizeof(text), "%04d-%02d-%02dT%02d:%02d:%02d.%06lldZ", year, month, day,
                  hour, minute, second, static_cast<long long>(micros));
  }
  return text;
}

}  // namespace nadir::core
