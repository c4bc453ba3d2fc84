#pragma once
// Calendar dates in UTC and microseconds since 1970-01-01T00:00:00Z (the
// Unix epoch, what LCM log event times count). Proleptic Gregorian calendar,
// no leap seconds (as Unix time), no time zones, no locale.

#include <cstdint>
#include <string>
#include <string_view>

namespace nadir::core {

// 2000-01-01T00:00:00Z. nadir takes a time stamp before it for sim time
// (counting from 0 at a run's start) and one after it for a date.
inline constexpr std::int64_t kYear2000Utime = 946'684'800'000'000;

// "2024-06-21T10:00:00Z", with optional fractional seconds ("...:00.25Z");
// the Z (UTC) is required. Throws std::invalid_argument naming the text and
// what is wrong (a field out of range, February 30th, no Z ...).
std::int64_t utimeFromUtc(std::string_view text);

// The inverse: "2024-06-21T10:00:00Z", with ".ffffff" when the microseconds
// are not zero.
std::string utcFromUtime(std::int64_t utime);

// Days since 1970-01-01 of a date, and the date of a day (civil_from_days).
std::int64_t daysFromCivil(int year, int month, int day);
void civilFromDays(std::int64_t days, int& year, int& month, int& day);

}  // namespace nadir::core
