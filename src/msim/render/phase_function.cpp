#include "msim/render/phase_function.hpp"

#include <stdexcept>
#include <string>

namespace msim::render {

HenyeyGreenstein::HenyeyGreenstein(double g) : g_(g), a_(1.0 - g * g), b_(1.0 + g * g), c_(2.0 * g) {
  if (!(g > -1.0 && g < 1.0))
    throw std::invalid_argument("Henyey-Greenstein asymmetry g must be in (-1, 1), got " + std::to_string(g));
}

double asymmetryFromStamMoment(double muBar) {
  if (!(muBar > -3.0 && muBar < 3.0))
    throw std::invalid_argument("Stam's phase first moment mu_bar must be in (-3, 3), got " + std::to_string(muBar));
  return muBar / 3.0;
}

}  // namespace msim::render
