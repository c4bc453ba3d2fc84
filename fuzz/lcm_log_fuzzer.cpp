// The LCM log reader on any bytes: every event it returns lies inside the file,
// and reading again from the first event gives the same events.
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "core/lcm_log.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = nadir::fuzz::writeInput(data, size, "input.lcmlog");
  try {
    nadir::core::LcmLogReader reader(path);
    std::vector<std::int64_t> offsets;
    while (const auto event = reader.next()) {
      const auto event_bytes =
          static_cast<std::int64_t>(event->channel.size() + event->data.size());
      NADIR_FUZZ_REQUIRE(event->offset >= 0 && event->offset + event_bytes <= reader.fileSize());
      offsets.push_back(event->offset);
    }
    (void)reader.damageReport();
    if (!offsets.empty()) {
      reader.seek(offsets.front());
      for (const std::int64_t offset : offsets) {
        const auto again = reader.next();
        NADIR_FUZZ_REQUIRE(again.has_value() && again->offset == offset);
      }
      NADIR_FUZZ_REQUIRE(!reader.next().has_value());
      reader.seek(reader.fileSize() / 2);
      while (reader.next()) {
      }
    }
  } catch (const nadir::core::LogError&) {
  }
  return 0;
}
