#include "msim/fluid/vortex/vortex_particles.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace msim::fluid {

namespace {

template <typename V>
bool allFinite(const V& v) {
  for (int i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

}  // namespace

void requireValidVortexRadius(double radius, const char* what) {
  if (!(std::isfinite(radius) && radius > 0.0)) {
    std::ostringstream message;
    message << what << ": the vortex particle radius must be a finite length > 0 m, got " << radius;
    throw std::invalid_argument(message.str());
  }
}

void requireValidVortexStrength(double strength, const char* what) {
  if (!(std::isfinite(strength) && strength >= 0.0)) {
    std::ostringstream message;
    message << what << ": the vortex particle strength eps_p must be finite and >= 0, got " << strength;
    throw std::invalid_argument(message.str());
  }
}

void requireValidVortexTimestep(double dt, const char* where) {
  if (!(std::isfinite(dt) && dt >= 0.0)) {
    std::ostringstream message;
    message << where << ": the time step must be finite and >= 0 s, got " << dt;
    throw std::invalid_argument(message.str());
  }
}

template <int D>
std::size_t VortexParticles<D>::add(const Vec<D>& position, const VortexVector<D>& vorticity, double radius,
                                    double strength) {
  if (!allFinite(position)) throw std::invalid_argument("vortex particle: the position must be finite");
  if (!allFinite(vorticity)) throw std::invalid_argument("vortex particle: the vorticity must be finite");
  requireValidVortexRadius(radius, "vortex particle");
  requireValidVortexStrength(strength, "vortex particle");
  positions_.push_back(position.template cast<float>());
  vorticities_.push_back(vorticity);
  radii_.push_back(radius);
  strengths_.push_back(strength);
  return positions_.size() - 1;
}

template <int D>
void VortexParticles<D>::reserve(std::size_t n) {
  positions_.reserve(n);
  vorticities_.reserve(n);
  radii_.reserve(n);
  strengths_.reserve(n);
}

template <int D>
void VortexParticles<D>::clear() {
  positions_.clear();
  vorticities_.clear();
  radii_.clear();
  strengths_.clear();
}

template <int D>
double VortexParticles<D>::maxRadius() const {
  return radii_.empty() ? 0.0 : *std::max_element(radii_.begin(), radii_.end());
}

template class VortexParticles<2>;
template class VortexParticles<3>;

}  // namespace msim::fluid
