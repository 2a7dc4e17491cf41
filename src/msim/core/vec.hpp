#pragma once
// Small fixed-size vectors shared by every module. Eigen's fixed-size types give us
// arithmetic, norms and dot products; the aliases keep 2D and 3D code one template.
#include <Eigen/Core>

namespace msim {

template <int D> using Vec = Eigen::Matrix<double, D, 1>;
template <int D> using Vecf = Eigen::Matrix<float, D, 1>;
template <int D> using IVec = Eigen::Matrix<int, D, 1>;

using Vec2 = Vec<2>;
using Vec3 = Vec<3>;
using IVec2 = IVec<2>;
using IVec3 = IVec<3>;

}  // namespace msim
