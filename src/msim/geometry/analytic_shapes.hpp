#pragma once
// Shapes with closed-form exact signed distances, in 2D (circle, rectangle, stadium, half-plane)
// and 3D (sphere, box, capsule, capped cylinder, half-space).
#include <algorithm>
#include <cmath>

#include "msim/geometry/shape.hpp"

namespace msim::geometry {

template <int D>
class Sphere final : public Shape<D> {
 public:
  Sphere(const Vec<D>& center, double radius) : center_(center), radius_(radius) {}
  double distance(const Vec<D>& x) const override { return (x - center_).norm() - radius_; }
  Bounds<D> bounds() const override {
    return {center_ - Vec<D>::Constant(radius_), center_ + Vec<D>::Constant(radius_)};
  }

 private:
  Vec<D> center_;
  double radius_;
};

// Axis-aligned box [min, max]. Outside, the distance is Euclidean to the nearest face, edge or
// corner; inside, it is minus the distance to the nearest face.
template <int D>
class Box final : public Shape<D> {
 public:
  Box(const Vec<D>& min, const Vec<D>& max) : min_(min), max_(max) {}
  double distance(const Vec<D>& x) const override {
    const Vec<D> center = 0.5 * (min_ + max_);
    const Vec<D> halfSize = 0.5 * (max_ - min_);
    const Vec<D> q = (x - center).cwiseAbs() - halfSize;  // per-axis distance outside the slab
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  }
  Bounds<D> bounds() const override { return {min_, max_}; }

 private:
  Vec<D> min_;
  Vec<D> max_;
};

// All points within `radius` of the segment a-b (a sphere when a == b).
template <int D>
class Capsule final : public Shape<D> {
 public:
  Capsule(const Vec<D>& a, const Vec<D>& b, double radius) : a_(a), b_(b), radius_(radius) {}
  double distance(const Vec<D>& x) const override {
    const Vec<D> ab = b_ - a_;
    const double lengthSq = ab.squaredNorm();
    const double t = lengthSq > 0.0 ? std::clamp((x - a_).dot(ab) / lengthSq, 0.0, 1.0) : 0.0;
    return (x - (a_ + t * ab)).norm() - radius_;
  }
  Bounds<D> bounds() const override {
    const Vec<D> r = Vec<D>::Constant(radius_);
    return {a_.cwiseMin(b_) - r, a_.cwiseMax(b_) + r};
  }

 private:
  Vec<D> a_;
  Vec<D> b_;
  double radius_;
};

// Capped cylinder of `radius` around the segment a-b (flat ends at a and b; a rectangle in 2D).
// Exact: the distance to the flat caps and to the side combine like a 2D box in (axial, radial).
template <int D>
class Cylinder final : public Shape<D> {
 public:
  // a != b (callers validate).
  Cylinder(const Vec<D>& a, const Vec<D>& b, double radius)
      : a_(a), axis_((b - a).normalized()), halfLength_(0.5 * (b - a).norm()), radius_(radius) {}
  double distance(const Vec<D>& x) const override {
    const Vec<D> d = x - a_;
    const double t = d.dot(axis_);
    const double radial = (d - t * axis_).norm() - radius_;
    const double axial = std::abs(t - halfLength_) - halfLength_;
    const double outside = std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
    return outside + std::min(std::max(radial, axial), 0.0);
  }
  Bounds<D> bounds() const override {
    // Per axis the disc of an end cap reaches radius * sqrt(1 - axis_k^2) from its centre.
    const Vec<D> b = a_ + 2.0 * halfLength_ * axis_;
    Vec<D> r;
    for (int k = 0; k < D; ++k) r[k] = radius_ * std::sqrt(std::max(0.0, 1.0 - axis_[k] * axis_[k]));
    return {a_.cwiseMin(b) - r, a_.cwiseMax(b) + r};
  }

 private:
  Vec<D> a_, axis_;
  double halfLength_, radius_;
};

// Half-space behind the plane through `point`: the solid is on the side opposite `normal`.
template <int D>
class Plane final : public Shape<D> {
 public:
  // `normal` need not be unit length but must be non-zero.
  Plane(const Vec<D>& point, const Vec<D>& normal) : point_(point), normal_(normal.normalized()) {}
  double distance(const Vec<D>& x) const override { return (x - point_).dot(normal_); }
  Bounds<D> bounds() const override { return Bounds<D>::infinite(); }

 private:
  Vec<D> point_;
  Vec<D> normal_;
};

}  // namespace msim::geometry
