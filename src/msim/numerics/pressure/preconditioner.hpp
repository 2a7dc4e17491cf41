#pragma once
// Preconditioner: z = M^{-1} r for preconditioned CG. M must be symmetric positive definite on
// the fluid cells (CG's short recurrences rely on it) and leave excluded cells at 0.
#include <vector>

namespace msim::numerics {

class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  virtual void apply(const std::vector<float>& r, std::vector<float>& z) = 0;
};

}  // namespace msim::numerics
