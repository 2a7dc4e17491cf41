#pragma once
// Henyey-Greenstein phase function (Stam eq. 5.2) with Stam's normalisation: the phase function
// integrates to 4 pi over the sphere, (1 / 4 pi) * integral p(s . s') ds' = 1, so that the
// scattering functional S{I} = (1 / 4 pi) integral p I ds' (eq. 5.3) of a constant I is I.
//
//   p(mu) = (1 - g^2) / (1 + g^2 - 2 g mu)^(3/2),   mu = cosine of the scattering angle,
//
// where g in (-1, 1) is the usual asymmetry, the mean cosine (1 / 4 pi) integral p mu ds' = g:
// g > 0 scatters forward (clouds: about 0.85), g < 0 backward, g = 0 is isotropic (p = 1).
// Stam writes the parameter as the "first moment" mu_bar = (3/2) integral_{-1}^{1} mu p(mu) dmu,
// which for this p is 3 g (Stam ch. 5.1, seed notes T11/T12). The renderer takes g, the value
// every other source quotes; asymmetryFromStamMoment converts a value taken from the thesis.
#include <cmath>

namespace msim::render {

class HenyeyGreenstein {
 public:
  // std::invalid_argument unless -1 < g < 1 (|g| = 1 is a delta function).
  explicit HenyeyGreenstein(double g);

  // mu = cosine between the propagation directions of the incident and the scattered light.
  double operator()(double mu) const {
    const double d = b_ - c_ * mu;
    return a_ / (d * std::sqrt(d));
  }
  double g() const { return g_; }

 private:
  double g_, a_, b_, c_;  // g, 1 - g^2, 1 + g^2, 2 g
};

// g = mu_bar / 3 for Stam's first moment mu_bar (in (-3, 3)); std::invalid_argument outside.
double asymmetryFromStamMoment(double muBar);

}  // namespace msim::render
