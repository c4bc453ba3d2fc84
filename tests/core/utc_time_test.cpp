// UTC dates and Unix microseconds, against values worked out with Python's
// datetime (a separate implementation of the same calendar).
#include "core/utc_time.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace nadir::core {
namespace {

TEST(UtcTime, KnownInstants) {
  // Python: datetime.fromisoformat(s).replace(tzinfo=timezone.utc).timestamp().
  EXPECT_EQ(utimeFromUtc("1970-01-01T00:00:00Z"), 0);
  EXPECT_EQ(utimeFromUtc("2024-06-21T10:00:00Z"), 1718964000LL * 1'000'000);
  EXPECT_EQ(utimeFromUtc("2000-02-29T00:00:00Z"), 951782400LL * 1'000'000);
  EXPECT_EQ(utimeFromUtc("2100-03-01T00:00:00Z"), 4107542400LL * 1'000'000);
  EXPECT_EQ(utimeFromUtc("2023-11-14T22:13:20Z"), 1700000000LL * 1'000'000);
  EXPECT_EQ(utimeFromUtc("2038-01-19T03:14:08Z"), 2147483648LL * 1'000'000);
  EXPECT_EQ(utimeFromUtc("2023-11-14T22:13:20.25Z"), 1700000000LL * 1'000'000 + 250'000);
  EXPECT_EQ(utimeFromUtc("2023-11-14T22:13:20.000001Z"), 1700000000LL * 1'000'000 + 1);
}

TEST(UtcTime, FormatsBack) {
  EXPECT_EQ(utcFromUtime(0), "1970-01-01T00:00:00Z");
  EXPECT_EQ(utcFromUtime(1718964000LL * 1'000'000), "2024-06-21T10:00:00Z");
  EXPECT_EQ(utcFromUtime(951782400LL * 1'000'000 + 86399'000'000), "2000-02-29T23:59:59Z");
  EXPECT_EQ(utcFromUtime(1700000000LL * 1'000'000 + 250'000), "2023-11-14T22:13:20.250000Z");
  for (const char* text :
       {"1999-12-31T23:59:59Z", "2024-02-29T12:00:00Z", "2401-03-01T00:00:00Z"}) {
    EXPECT_EQ(utcFromUtime(utimeFromUtc(text)), text);
  }
}

TEST(UtcTime, BadTextIsRefusedNamingIt) {
  for (const char* text :
       {"2024-06-21T10:00:00", "2024-06-21 10:00:00Z", "2023-02-29T00:00:00Z",
        "2024-13-01T00:00:00Z", "2024-06-21T24:00:00Z", "1969-12-31T23:59:59Z",
        "2024-6-21T10:00:00Z", "", "2024-06-21T10:00:00Zx", "2024-06-21T10:00:00.Z",
        "2024-06-21T10:00:00.1234567Z", "2024-06-21T10:00:-1Z"}) {
    try {
      utimeFromUtc(text);
      ADD_FAILURE() << "'" << text << "': no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + text + "'"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace nadir::core
