#pragma once
// The choices Selle ch. 2 compares: the first-order building block, the scheme built from it,
// the new-extrema limiter of ch. 2.7 and the first-order reversion near solids of ch. 2.9.

namespace msim::numerics {

// First-order step every scheme is built from.
enum class BuildingBlock {
  Upwind,          // forward Euler + upwind differences per axis (eq. 2.3); stable for CFL <= 1
  SemiLagrangian,  // trace the characteristic back, D-linear interpolation (ch. 2.3); any CFL
};

enum class AdvectionScheme {
  FirstOrder,  // one building-block step
  BFECC,       // forward, backward, correct phi^n by e = (phi_hat^n - phi^n)/2, forward again (3 steps)
  MacCormack,  // forward, backward, phi^{n+1} = phi_hat^{n+1} - e (2 steps; ch. 2.4)
};

// What to do where the error-corrected value leaves the range of the samples the first forward
// step read (its interpolation stencil, or its upwind stencil) (ch. 2.7).
enum class ExtremaLimiter {
  None,
  ClampExtrema,        // clamp into [min, max] of those samples
  RevertToFirstOrder,  // use the first forward step's value instead (Selle's preferred choice)
};

// How the semi-Lagrangian block traces the characteristic back from a sample at X.
enum class BackTrace {
  Euler,  // X - dt V(X): Selle's straight ray (ch. 2.3)
  RK2,    // midpoint rule, X - dt V(X - dt/2 V(X)): second order in space-varying velocity
};

struct AdvectionSettings {
  BuildingBlock block = BuildingBlock::SemiLagrangian;
  AdvectionScheme scheme = AdvectionScheme::MacCormack;
  ExtremaLimiter limiter = ExtremaLimiter::RevertToFirstOrder;
  BackTrace trace = BackTrace::RK2;
  // Ch. 2.9: samples whose forward or backward stencil reads a solid sample take the first-order
  // value, because the error estimate mixes fluid and solid data there.
  bool firstOrderNearSolids = true;
};

}  // namespace msim::numerics
