#pragma once
// The time horizons and neighbour bands of long-range collision avoidance (Golas ch. 3.4, 3.6):
// level i of the lookahead sees the crowd as it will be dt_i = 2^(i-1) dt ahead (dt_0 = 0, the
// plain local avoidance), its agents' effective radii shrunk by the coarsening factor c per level
// (their predicted positions are uncertain), and, in the discrete lookahead, the agents whose
// current distance lies in the band [R + 2 v_max dt_(i-1), R + 2 v_max dt_i): two agents' distance
// changes by at most 2 v_max dt_i within dt_i, so an agent beyond that band cannot come within R
// by then.
namespace msim::crowd::lookahead {

struct HorizonSchedule {
  double baseStep = 0.01;     // dt [s] (the seed: the simulation step)
  int levels = 8;             // i_max (the seed's demos: 8; up to 16)
  double coarsening = 2.0;    // c, shared by the continuum pyramid and the effective radii
  double neighbourDist = 3.0; // R: level 0's neighbours [m]
  double maxSpeed = 1.6;      // v_max of any agent [m/s]

  // dt_i: 0 for i = 0, 2^(i-1) dt for 1 <= i <= levels.
  double horizon(int level) const;
  // Where the band of `level` begins: R for level 1 (level 0 is [0, R)), R + 2 v_max dt_(i-1)
  // beyond; bandStart(levels + 1) ends the last band.
  double bandStart(int level) const;
  // The level whose band holds an agent at `distance` (0 within R), or -1 beyond the last band.
  int levelOfDistance(double distance) const;
  // r / c^i: the radius an agent of radius r blocks with at level i (the seed's simplified rule).
  double effectiveRadius(double radius, int level) const;
};

// The level whose band holds `distance`: 0 below bandStart(1) = R, i for bandStart(i) <= distance
// < bandStart(i + 1), -1 beyond the last band. bandStart(i) gives band i's start (any precision).
template <typename T, typename BandStart>
int levelInBands(T distance, int levels, BandStart&& bandStart) {
  if (distance < bandStart(1)) return 0;
  for (int i = 1; i <= levels; ++i)
    if (distance < bandStart(i + 1)) return i;
  return -1;
}

// The radius within which a disc of radius r whose centre is uncertain, an isotropic Gaussian of
// standard deviation sigma per axis about its predicted position, covers a point with probability
// at least p (Fig. 3.2: 0.4): r while sigma is 0, and 0 once even the predicted centre is covered
// with less than p, 1 - exp(-r^2 / (2 sigma^2)) < p (sigma > 0.989 r at p = 0.4). For p < 1/2 it
// first grows a little (a point just outside the disc is covered whenever the centre drifts
// towards it, which happens with probability near 1/2): at p = 0.4 up to 1.03 r near sigma =
// r / 4, shrinking from there on. The seed's agents use the simpler r / c^i; this is the rule it
// simplifies.
double gaussianCoverageRadius(double radius, double sigma, double p);

}  // namespace msim::crowd::lookahead
