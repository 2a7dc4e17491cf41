#pragma once
// Shapes made from other shapes: the complement (a container is everything outside its cavity),
// a translated copy (a body moving without turning), a rigidly moved copy (a body that turns) and
// a grid-sampled copy (a mesh queried per particle and step is O(triangles) per call; a
// sampled distance is O(1), exact enough within the sampling cell near the surface).
#include <limits>
#include <memory>

#include "msim/core/interpolation.hpp"
#include "msim/geometry/rigid_motion.hpp"
#include "msim/geometry/shape.hpp"

namespace msim::geometry {

// Everything outside `inner`: distance -inner(x). Unbounded.
template <int D>
class Inverted final : public Shape<D> {
 public:
  explicit Inverted(std::shared_ptr<const Shape<D>> inner) : inner_(std::move(inner)) {}
  double distance(const Vec<D>& x) const override { return -inner_->distance(x); }
  Bounds<D> bounds() const override { return Bounds<D>::infinite(); }

 private:
  std::shared_ptr<const Shape<D>> inner_;
};

// `inner` moved by `offset`: distance inner(x - offset).
template <int D>
class Translated final : public Shape<D> {
 public:
  Translated(std::shared_ptr<const Shape<D>> inner, const Vec<D>& offset) : inner_(std::move(inner)), offset_(offset) {}
  double distance(const Vec<D>& x) const override { return inner_->distance(x - offset_); }
  Bounds<D> bounds() const override {
    const Bounds<D> b = inner_->bounds();
    return {b.min + offset_, b.max + offset_};
  }

 private:
  std::shared_ptr<const Shape<D>> inner_;
  Vec<D> offset_;
};

// `inner` (standing as at t = 0) moved by `motion` to time t: distance inner(motion^-1(x)), exact
// since a rigid motion keeps distances. The rotation is taken once, not per query.
class RigidlyMoved final : public Shape<3> {
 public:
  RigidlyMoved(std::shared_ptr<const Shape<3>> inner, const RigidMotion& motion, double t)
      : inner_(std::move(inner)), rotation_(motion.rotation(t)), from_(motion.center), to_(motion.centerAt(t)) {}
  double distance(const Vec3& x) const override { return inner_->distance(from_ + rotation_.transpose() * (x - to_)); }
  // The box around the moved corners of the inner box.
  Bounds<3> bounds() const override {
    const Bounds<3> b = inner_->bounds();
    if (!b.min.allFinite() || !b.max.allFinite()) return Bounds<3>::infinite();
    Bounds<3> out{Vec3::Constant(std::numeric_limits<double>::infinity()),
                  Vec3::Constant(-std::numeric_limits<double>::infinity())};
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 c((corner & 1) ? b.max.x() : b.min.x(), (corner & 2) ? b.max.y() : b.min.y(),
                   (corner & 4) ? b.max.z() : b.min.z());
      const Vec3 moved = to_ + rotation_ * (c - from_);
      out.min = out.min.cwiseMin(moved);
      out.max = out.max.cwiseMax(moved);
    }
    return out;
  }

 private:
  std::shared_ptr<const Shape<3>> inner_;
  Eigen::Matrix3d rotation_;
  Vec3 from_, to_;  // the centre at t = 0 and at t
};

// `exact` sampled at the cell centres of `spec` and interpolated D-linearly inside it; outside
// the sampled box the exact shape answers.
template <int D>
class Sampled final : public Shape<D> {
 public:
  Sampled(std::shared_ptr<const Shape<D>> exact, const GridSpec<D>& spec)
      : exact_(std::move(exact)), samples_(exact_->distanceField(spec)) {
    lo_ = spec.origin + Vec<D>::Constant(0.5 * spec.dx);
    hi_ = spec.origin + spec.extent() - Vec<D>::Constant(0.5 * spec.dx);
  }
  double distance(const Vec<D>& x) const override {
    if ((x.array() < lo_.array()).any() || (x.array() > hi_.array()).any()) return exact_->distance(x);
    return sampleLinear<D>(samples_, x);
  }
  Bounds<D> bounds() const override { return exact_->bounds(); }

 private:
  std::shared_ptr<const Shape<D>> exact_;
  Grid<float, D> samples_;
  Vec<D> lo_, hi_;
};

}  // namespace msim::geometry
