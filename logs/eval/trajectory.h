#pragma once
// What evaluation adds to core/trajectory.h: its error type and timestamp
// association (as evo does it).

#include <cstddef>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/trajectory.h"

namespace nadir::eval {

// Any evaluation error: too few poses to compare, a bad option. The message
// says what is wrong, in one line.
class EvalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Index pairs (ref, est) of poses with matching stamps, as evo's
// sync.associate_trajectories (nearest stamp within t_max_diff_s), made one to
// one: a pair is kept when each stamp is the other's nearest and they differ by
// at most t_max_diff_s. Both inputs sorted by time; pairs come in time order.
std::vector<std::pair<std::size_t, std::size_t>> associate(const core::Trajectory& ref,
                                                           const core::Trajectory& est,
                                                           double t_max_diff_s);

}  // namespace nadir::eval
