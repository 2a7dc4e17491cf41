#pragma once
// The hybrid's blend of continuum and discrete lookahead (Golas ch. 3.9): v = (1 - w) v_disc +
// w v_cont (3.11) with w = w_rho w_sigma, favouring the continuum where the crowd is dense (3.12)
// and moves uniformly (3.13), the discrete agents where it is sparse or disordered.
namespace msim::crowd::lookahead {

struct BlendThresholds {
  double continuumFrom = 2.0;   // rho_cmin [1/m^2]: pure discrete below
  double discreteUpTo = 4.0;    // rho_dmax [1/m^2]: pure continuum above
  double uniformBelow = 1.0;    // c_1: w_sigma = 1 while sigma_v <= c_1 vbar
  double disorderedFrom = 2.0;  // c_2: w_sigma = 0 once sigma_v >= c_2 vbar
  double stillSpeed = 0.05;     // [m/s]: below this mean speed the ratio is undefined; w_sigma = 1 if sigma_v is below it too, else 0
};

// w_rho = clamp((rho - rho_cmin) / (rho_dmax - rho_cmin), 0, 1)  (3.12)
double densityWeight(double density, const BlendThresholds& t);
// w_sigma = clamp((c_2 vbar - sigma_v) / ((c_2 - c_1) vbar), 0, 1)  (3.13)
double varianceWeight(double speedDeviation, double meanSpeed, const BlendThresholds& t);
// w = w_rho w_sigma
double blendWeight(double density, double speedDeviation, double meanSpeed, const BlendThresholds& t);

}  // namespace msim::crowd::lookahead
