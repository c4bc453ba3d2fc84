#pragma once
// An emulator of the SCAMP-5 pixel processor array (PPA): 256 x 256 processing
// elements (PEs), each with a photodiode (PIX), analog registers and 1-bit
// digital registers, all executing the same instruction at once. Programs
// ("kernels") are sequences of calls on this class, as they are on the chip,
// and every call that is a chip instruction is counted.
//
// Layout. PE (x, y): x = column, growing east (image right); y = row, growing
// south (image down). Direction North is the neighbour at y - 1.
//
// Analog registers A..F and NEWS hold values in "counts" (the chip's 8-bit
// readout scale), saturating at [kAnalogMin, kAnalogMax]. As on the chip, an
// analog transfer writes the NEGATED sum of its sources (bus); the macros
// (mov, add, sub, ...) are built from two or more such transfers and count as
// that many instructions. Analog writes happen only in PEs whose FLAG is 1;
// each write may add Gaussian noise (PpaParams::analog_noise_sigma) before
// saturating. A macro reads its sources before it writes and leaves NEWS
// holding one of its intermediates, so NEWS is clobbered (but may be a source).
//
// Digital registers R0..R12 and FLAG: bit planes packed 64 PEs a word, row
// major, 4 words a row: bit i of word (y * 4 + w) is PE (x = 64 w + i, y).
// Digital instructions are not conditional on FLAG.
//
// No LCM, no GL: plain data in, plain data out.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace nadir::ppa {

inline constexpr int kWidth = 256;
inline constexpr int kHeight = 256;
inline constexpr int kWordsPerRow = kWidth / 64;
inline constexpr int kWordsPerPlane = kHeight * kWordsPerRow;
inline constexpr float kAnalogMin = -128.0f;
inline constexpr float kAnalogMax = 127.0f;

enum class Areg : std::uint8_t { A, B, C, D, E, F, NEWS };
inline constexpr int kAnalogRegisters = 7;
enum class Dreg : std::uint8_t { R0, R1, R2, R3, R4, R5, R6, R7, R8, R9, R10, R11, R12 };
inline constexpr int kDigitalRegisters = 13;
enum class Dir : std::uint8_t { North, East, South, West };

struct PpaParams {
  // Standard deviation of the noise each analog write adds, counts; 0 = none.
  double analog_noise_sigma = 0.0;
  std::uint64_t noise_seed = 1;
  // PIX response to the light (0..255 per PE): "linear" (gain * light, saturating)
  // or "log", a high-dynamic-range response: kAnalogMax * log(1 + gain * light)
  // / log(1 + gain * 255), so dark and bright areas both keep contrast.
  std::string pix_response = "log";
  double pix_gain = 1.0;
};

struct BoundingBox {
  bool found = false;
  int x_min = 0, y_min = 0, x_max = 0, y_max = 0;  // inclusive
};

struct Event {
  int x = 0, y = 0;
};

using DigitalPlane = std::array<std::uint64_t, kWordsPerPlane>;

class Ppa {
 public:
  // Throws std::invalid_argument for a bad parameter (unknown pix_response, negative
  // or non-finite sigma, pix_gain not > 0). All registers start at 0, FLAG at 1.
  explicit Ppa(const PpaParams& params = {});

  // ---- host side (not chip instructions)
  // The light falling on the array for the next exposure: kWidth * kHeight gray
  // values, row major.
  void setLight(const std::uint8_t* gray);
  // Single-PE reads throw std::out_of_range outside the array.
  float analog(Areg reg, int x, int y) const;
  bool digital(Dreg reg, int x, int y) const;
  bool flag(int x, int y) const;
  const std::vector<float>& analogPlane(Areg reg) const;
  const DigitalPlane& digitalPlane(Dreg reg) const;
  // Loads a plane directly (tests, and to seed a register with a host image).
  // Analog values are clamped to [kAnalogMin, kAnalogMax]; a vector that is not
  // kWidth * kHeight long throws std::invalid_argument.
  void loadAnalog(Areg reg, const std::vector<float>& values);
  void loadDigital(Dreg reg, const DigitalPlane& plane);
  // Chip instructions executed since construction or the last reset.
  std::uint64_t instructions() const { return instructions_; }
  void resetInstructionCount() { instructions_ = 0; }

  // ---- analog: one instruction each, written only where FLAG = 1
  // dst = PIX: the response to the current light.
  void getImage(Areg dst);
  // dst = -src.
  void bus(Areg dst, Areg src);
  // dst = -(src1 + src2).
  void bus(Areg dst, Areg src1, Areg src2);
  // dst = -(the NEWS register of the neighbour in direction from); 0 beyond the array's edge.
  void busFrom(Areg dst, Dir from);
  // FLAG = (src > 0) in every PE (unconditional).
  void where(Areg src);
  // FLAG = src in every PE.
  void whereDigital(Dreg src);
  // FLAG = 1 everywhere.
  void all();

  // ---- analog macros, built of the instructions above (counted as such)
  // dst = src (2): NEWS = -src; dst = -NEWS.
  void mov(Areg dst, Areg src);
  // dst = src1 + src2 (2): NEWS = -(src1 + src2); dst = -NEWS.
  void add(Areg dst, Areg src1, Areg src2);
  // dst = src1 - src2 (3): NEWS = -src2; NEWS = -(src1 + NEWS); dst = -NEWS.
  void sub(Areg dst, Areg src1, Areg src2);
  // dst = -src (1): one transfer.
  void neg(Areg dst, Areg src);
  // dst = |src| in every PE whatever FLAG was (6): all(); mov(dst, src);
  // where(NEWS); bus(dst, src); all(). FLAG is all on return.
  void abs(Areg dst, Areg src);
  // dst = src of the neighbour in direction from, 0 beyond the edge (2):
  // bus(NEWS, src); busFrom(dst, from).
  void movFrom(Areg dst, Areg src, Dir from);

  // ---- digital: one instruction each (unconditional)
  void set(Dreg dst);                          // dst = 1
  void clr(Dreg dst);                          // dst = 0
  void mov(Dreg dst, Dreg src);                // dst = src
  void notOp(Dreg dst, Dreg src);              // dst = !src
  void nor(Dreg dst, Dreg src1, Dreg src2);    // dst = !(src1 | src2)
  void orOp(Dreg dst, Dreg src1, Dreg src2);   // dst = src1 | src2
  void andOp(Dreg dst, Dreg src1, Dreg src2);  // dst = src1 & src2 (2 on the chip: NOR of NOTs)
  void xorOp(Dreg dst, Dreg src1, Dreg src2);  // dst = src1 ^ src2 (3)
  void storeFlag(Dreg dst);                    // dst = FLAG
  // dst(p) = src(the neighbour of p in direction from); PEs whose neighbour is
  // beyond the edge get edge_value.
  void movFrom(Dreg dst, Dreg src, Dir from, bool edge_value = false);
  // The asynchronous flood: target spreads to 4-connected neighbours through
  // PEs where mask = 1 until nothing changes (iterations = 0) or for that many
  // steps; one step is target |= mask & (target's 4-neighbourhood), so a target
  // PE spreads to its neighbours whatever its own mask, and target PEs stay set
  // whatever the mask. One instruction.
  void flood(Dreg target, Dreg mask, int iterations = 0);
  // target = the PEs of mask 4-connected (within mask) to a PE of mask on the
  // array's border: a flood seeded from the border. target's old content is
  // replaced. One instruction.
  void floodFromBorder(Dreg target, Dreg mask);

  // ---- global readouts: one instruction each
  bool globalOr(Dreg src);
  int globalCount(Dreg src);
  // Coordinates of set PEs in raster order (row by row, x growing within a
  // row), at most max_events (none if max_events <= 0).
  std::vector<Event> scanEvents(Dreg src, int max_events);
  BoundingBox boundingBox(Dreg src);

 private:
  std::vector<float>& plane(Areg reg);
  DigitalPlane& dplane(Dreg reg);
  // Runs an element-wise analog kernel of `transfers` transfers: calls
  // kernel(noise, write) with the noise source and the FLAG-conditional writer
  // that fit the current parameters and FLAG (defined in ppa_array.cpp).
  template <class Kernel>
  void runAnalog(int transfers, Kernel&& kernel);
  template <class FirstTransfer>
  void viaNews(Areg dst, FirstTransfer first);
  // Updates flag_all_ after FLAG changed.
  void flagChanged();
  // Fills noise_[k] with a fresh plane of Gaussian noise, sigma = analog_noise_sigma.
  void makeNoise(int k);
  // Grows `fill` (seeds, a subset of mask) to the 4-connected components of mask
  // that contain a seed.
  void fillComponents(DigitalPlane& fill, const DigitalPlane& mask);

  PpaParams params_;
  std::array<float, 256> pix_lut_{};
  std::array<std::vector<float>, kAnalogRegisters> analog_;
  std::array<DigitalPlane, kDigitalRegisters> digital_{};
  DigitalPlane flag_{};
  bool flag_all_ = true;
  std::vector<float> pix_;
  std::vector<float> scratch_;
  std::array<std::vector<float>, 3> noise_;
  std::vector<std::uint32_t> noise_bits_;
  // The flood's westward propagate rows: 8 rows of 4 words for each row.
  std::vector<std::uint64_t> flood_scratch_;
  std::uint64_t instructions_ = 0;
  std::uint64_t noise_counter_ = 0;
};

}  // namespace nadir::ppa
