#include "msim/crowd/speed_distribution.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace msim::crowd {

namespace {

[[noreturn]] void fail(const std::string& context, const std::string& field, const std::string& what) {
  throw std::invalid_argument(fmt::format("{}.{}: {}", context, field, what));
}

}  // namespace

void SpeedDistribution::validate(const std::string& context) const {
  const auto positive = [&](double v, const char* field) {
    if (!(std::isfinite(v) && v > 0.0)) fail(context, field, fmt::format("walking speeds must be > 0 m/s, got {}", v));
  };
  switch (kind) {
    case Kind::Fixed:
      positive(mean, "max_speed");
      break;
    case Kind::Uniform:
      positive(min, "speed_min");
      positive(max, "speed_max");
      if (!(max > min)) fail(context, "speed_max", fmt::format("{} m/s must exceed speed_min = {} m/s", max, min));
      break;
    case Kind::Normal:
      positive(mean, "max_speed");
      positive(min, "speed_min");
      if (!(std::isfinite(sd) && sd > 0.0)) fail(context, "speed_sd", fmt::format("must be > 0 m/s, got {}", sd));
      if (!(std::isfinite(max) && max > min))
        fail(context, "speed_max", fmt::format("{} m/s must exceed speed_min = {} m/s", max, min));
      if (!(mean >= min && mean <= max))
        fail(context, "max_speed", fmt::format("the mean {} m/s lies outside [speed_min, speed_max] = [{}, {}] m/s", mean, min, max));
      break;
  }
}

double SpeedDistribution::sample(Rng& rng) const {
  switch (kind) {
    case Kind::Fixed:
      return mean;
    case Kind::Uniform:
      return rng.uniform(min, max);
    case Kind::Normal:
      // The mean lies in [min, max] (validate), so half the range lies on one side of it and each
      // draw lands inside with probability at least P(0 <= Z <= (max - min) / (2 sd)).
      for (;;) {
        const double v = rng.normal(mean, sd);
        if (v >= min && v <= max) return v;
      }
  }
  return mean;
}

}  // namespace msim::crowd
