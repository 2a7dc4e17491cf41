#include "msim/core/float_environment.hpp"

#include <pmmintrin.h>
#include <xmmintrin.h>

namespace msim {

void flushSubnormalsToZero() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

}  // namespace msim
