#pragma once
// The floating-point environment msim's programs run in.

namespace msim {

// Flushes subnormal results to zero and reads subnormal inputs as zero (the SSE/AVX FTZ and DAZ
// modes) on the calling thread. Fields that decay towards zero (smoke density far from its
// source) otherwise pass through the subnormal range, where arithmetic is many times slower, and
// leave values near 1e-45 that are physically nothing. Call it on the main thread before the
// first parallel loop: oneTBB's worker threads take the floating-point settings of the thread
// that starts the task arena.
void flushSubnormalsToZero();

}  // namespace msim
