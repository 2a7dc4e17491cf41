#pragma once
// Contact and friction of particles with bodies (Selle ch. 6.5): bodies are signed distances,
// negative inside, moving rigidly (a velocity, and an angular velocity about a centre). The map
//   Gamma(v):  v*_N = max(v_N, v_BN),
//              v*_T = v_BT + max(0, 1 - mu (v*_N - v_N) / |v_T,rel|) v_T,rel,
//              Gamma(v) = v*_N N + v*_T
// stops a particle's motion into the body and takes tangential speed away in proportion to the
// normal speed it removed (Coulomb friction). A position step that would end inside the body is
// cut at the fraction theta = phi(x(n)) / (phi(x(n)) - phi(x~(n+1))) of the step where it meets
// the surface, and the rest of the step moves with Gamma of the step's velocity (ch. 6.5 step 2):
// the friction acts within the step. The earlier method (Bridson, Fedkiw & Anderson 2002, the
// seed's [16]) instead moves the whole step and projects the end point back out along N; it is
// kept as `ContactMethod::Projection` and slides too far (friction one step late).
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "msim/core/vec.hpp"
#include "msim/geometry/shape.hpp"

namespace msim::solids {

enum class ContactMethod { CrossingFraction, Projection };

struct ContactBody {
  std::shared_ptr<const geometry::Shape3> shape;  // the body at the end of the step (signed distance)
  Vec3 velocity = Vec3::Zero();                   // [m/s] of its centre
  double friction = 0.0;                          // mu
  Vec3 angularVelocity = Vec3::Zero();            // [rad/s], turning about
  Vec3 center = Vec3::Zero();                     // this point, where it stands at the step's end

  // The body's velocity at x: v + omega x (x - c).
  Vec3 velocityAt(const Vec3& x) const { return velocity + angularVelocity.cross(x - center); }
};

class BodyContact {
 public:
  explicit BodyContact(ContactMethod method = ContactMethod::CrossingFraction) : method_(method) {}
  void addBody(ContactBody body) { bodies_.push_back(std::move(body)); }
  // Replaces body b (a moving body's shape at the end of the next step).
  void setBody(std::size_t b, ContactBody body) { bodies_.at(b) = std::move(body); }
  bool empty() const { return bodies_.empty(); }

  // Gamma for body b at x (its outward normal there) applied to v.
  Vec3 gamma(std::size_t b, const Vec3& x, const Vec3& v) const;
  // Ch. 6.5 steps 1-2 for one particle: from x(n) with the step's velocity v over dt; returns
  // x(n+1); `body` is the body it met, or -1. The start's distance is phi(x(n)) + dt v_BN (a
  // moving body approaches).
  Vec3 move(const Vec3& x, const Vec3& v, double dt, int& body) const;
  // Particles that corrections after the contact step (strain limiting, self-collisions) left
  // inside a body are put back on its surface along its normal, their velocities through Gamma;
  // pinned ones are left alone. Returns how many moved.
  int pushOut(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<char>& pinned) const;
  // The same for one position; returns the body it was inside, or -1.
  int pushOut(Vec3& x) const;

 private:
  double distance(std::size_t b, const Vec3& x) const { return bodies_[b].shape->distance(x); }
  Vec3 normal(std::size_t b, const Vec3& x) const;

  ContactMethod method_;
  std::vector<ContactBody> bodies_;
};

}  // namespace msim::solids
