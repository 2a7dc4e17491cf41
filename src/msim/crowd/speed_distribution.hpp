#pragma once
// Walking speeds spread over a group instead of one value: real crowds mix fast and slow walkers,
// and evacuation guidelines (RiMEA's test 7, after Weidmann 1993's speeds by age) ask for a
// population's distribution. Fixed gives every agent `mean`; Uniform draws from [min, max]; Normal
// draws N(mean, sd) truncated to [min, max] (redrawn outside it).
#include <string>

#include "msim/core/rng.hpp"

namespace msim::crowd {

struct SpeedDistribution {
  enum class Kind { Fixed, Uniform, Normal };
  Kind kind = Kind::Fixed;
  double mean = 1.34;  // Fixed, Normal [m/s]
  double sd = 0.0;     // Normal [m/s]
  double min = 0.0, max = 0.0;  // Uniform's range, Normal's truncation [m/s]

  // std::invalid_argument naming `context` and the field: a speed that can be zero or negative, an
  // empty range, a mean outside it, a non-positive spread.
  void validate(const std::string& context) const;
  double sample(Rng& rng) const;
};

}  // namespace msim::crowd
