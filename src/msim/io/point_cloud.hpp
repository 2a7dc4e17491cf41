#pragma once
// PointCloud: particle positions plus named per-point float attributes, the exchange type of the
// point writers (PLY, VDB points). Positions are float because both formats store float and a
// float-in/float-out round trip is bit-exact.
#include <string>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::io {

struct PointAttribute {
  std::string name;
  std::vector<float> values;  // one per point
};

struct PointCloud {
  std::vector<Vecf<3>> positions;
  std::vector<PointAttribute> attributes;

  // The attribute with this name, or nullptr. The pointer refers into this cloud, so calling it on
  // a temporary (a cloud just read) would dangle: that overload is deleted.
  const PointAttribute* find(const std::string& name) const& {
    for (const auto& a : attributes)
      if (a.name == name) return &a;
    return nullptr;
  }
  const PointAttribute* find(const std::string& name) const&& = delete;
};

}  // namespace msim::io
