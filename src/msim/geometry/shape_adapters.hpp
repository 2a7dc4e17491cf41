#pragma once
// Shapes made from other shapes: the complement (a container is everything outside its cavity),
// a translated copy (a body moving without turning) and a grid-sampled copy (a mesh queried per particle and step is O(triangles) per call; a
// sampled distance is O(1), exact enough within the sampling cell near the surface).
#include <memory>

#include "msim/core/interpolation.hpp"
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
