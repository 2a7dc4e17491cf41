#include "msim/turbulence/curl_noise.hpp"

#include <array>
#include <cstdint>
#include <cmath>
#include <complex>
#include <algorithm>
#include <numbers>

#include "msim/core/linear_taps.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"
#include "msim/numerics/fft.hpp"

namespace msim::turbulence {

template <int D>
NoiseTile<D>::NoiseTile(std::uint64_t seed) {
  std::vector<int> dims(D, kSamples);
  dims.push_back(kTimeSamples);
  std::size_t n = 1;
  for (const int d : dims) n *= static_cast<std::size_t>(d);
  std::vector<std::complex<float>> modes(n, std::complex<float>(0.0f, 0.0f));
  // The spatial octave |n| in [4, 8) (wavelengths [1/2, 1) units on a 4-unit tile), shaped so the
  // velocity it makes follows k^(-5/3) within the octave too: a shell of radius k holds ~k^(D-1)
  // modes and the curl multiplies each mode's energy by k^2, so the potential's modes get
  // |n|^-(D + 8/3). Octaves scaled by 2^i with energies E_0 2^(-2i/3) then join into one power law
  // instead of a staircase. A Gaussian of 0.25 cycles per time unit over the temporal frequencies.
  auto temporal = [](int s) {  // the power of temporal frequency s / kPeriod (Nyquist excluded)
    if (2 * std::abs(s) == kTimeSamples) return 0.0;
    const double f = s / kPeriod;
    return std::exp(-0.5 * f * f / (0.25 * 0.25));
  };
  auto weight = [&](const auto& s) {
    double q = 0.0;
    for (int d = 0; d < D; ++d) q += double(s[d]) * s[d];
    if (q < 16.0 || q >= 64.0) return 0.0;
    return std::pow(q, -0.5 * (D + 8.0 / 3.0)) * temporal(s[D]);
  };
  // The correlation of two samples one time step apart, the same for every spatial mode: the
  // temporal spectrum's cosine transform at that lag.
  double power = 0.0, lagged = 0.0;
  for (int s = -kTimeSamples / 2; s < kTimeSamples / 2; ++s) {
    power += temporal(s);
    lagged += temporal(s) * std::cos(2.0 * std::numbers::pi * s / kTimeSamples);
  }
  adjacentCorrelation_ = static_cast<float>(lagged / power);
  // The components are independent realisations, two per transform: a + i b with a and b real
  // (their modes Hermitian) transforms to a real pair.
  const Rng noise(seed);
  if constexpr (D == 3) samples_.assign(n, Eigen::Array4f::Zero());
  else samples_.assign(n, 0.0f);
  for (int first = 0; first < kComponents; first += 2) {
    std::fill(modes.begin(), modes.end(), std::complex<float>(0.0f, 0.0f));
    for (int c = first; c < std::min(first + 2, kComponents); ++c) {
      const std::complex<float> unit = c == first ? std::complex<float>(1.0f, 0.0f) : std::complex<float>(0.0f, 1.0f);
      const Rng stream = noise.split(static_cast<std::uint64_t>(c));
      numerics::forEachMirrorPair(dims, [&](std::size_t a, std::size_t mirror, const auto& s) {
        const double w = weight(s);
        if (w == 0.0) return;  // zero on every self-mirrored mode (the mean, the Nyquist planes)
        Rng r = stream.split(a);
        const double size = r.normal();
        const std::complex<float> mode(std::polar(std::sqrt(w) * size, 2.0 * std::numbers::pi * r.uniform()));
        modes[a] += unit * mode;
        modes[mirror] += unit * std::conj(mode);
      });
    }
    numerics::FftNd(dims).inverse(modes);
    parallelFor(0, n, [&](std::size_t a) {
      if constexpr (D == 3) {
        samples_[a][first] = modes[a].real();
        if (first + 1 < kComponents) samples_[a][first + 1] = modes[a].imag();
      } else {
        samples_[a] = modes[a].real();
      }
    }, 1 << 14);
  }
  // Scale so that <|curl N|^2> = 1 for the noise as it is read (interpolated; row() keeps the
  // variance of the blend in time). Measured by central differences at 4096 random points and times.
  Rng sampler(seed ^ 0x5bd1e995ull);
  const double h = 1e-3;
  double sum = 0.0;
  const int points = 4096;
  for (int p = 0; p < points; ++p) {
    Vec<D> y;
    for (int d = 0; d < D; ++d) y[d] = sampler.uniform(0.0, kSide);
    const double t = sampler.uniform(0.0, kPeriod);
    // grad[c][d] = d N_c / d y_d
    double grad[3][3] = {};
    for (int d = 0; d < D; ++d) {
      Vec<D> e = Vec<D>::Zero();
      e[d] = h;
      const Vecf<3> difference = vector(y + e, t) - vector(y - e, t);
      for (int c = 0; c < kComponents; ++c) grad[c][d] = double(difference[c]) / (2.0 * h);
    }
    if constexpr (D == 3) {
      const double cx = grad[2][1] - grad[1][2], cy = grad[0][2] - grad[2][0], cz = grad[1][0] - grad[0][1];
      sum += cx * cx + cy * cy + cz * cz;
    } else {
      sum += grad[0][0] * grad[0][0] + grad[0][1] * grad[0][1];
    }
  }
  const float scale = static_cast<float>(std::sqrt(1.0 / (sum / points)));
  for (Sample& v : samples_) v *= scale;
}

template <int D>
LinearTap NoiseTile<D>::timeTap(double t) const {
  std::size_t slice = 1;
  for (int d = 0; d < D; ++d) slice *= static_cast<std::size_t>(kSamples);
  return periodicTap(t * (kTimeSamples / kPeriod), kTimeSamples, slice);
}

template <int D>
typename NoiseTile<D>::Row NoiseTile<D>::row(const Vec<D>& y, const LinearTap& time) const {
  std::array<LinearTap, D> taps;  // axes 1 .. D - 1, then time
  std::size_t stride = kSamples;
  for (int d = 1; d < D; ++d) {
    taps[d - 1] = periodicTap(y[d] * (kSamples / kSide), kSamples, stride);
    stride *= static_cast<std::size_t>(kSamples);
  }
  taps[D - 1] = time;
  Row r;
  for (int corner = 0; corner < kRowCorners; ++corner) {
    std::size_t offset = 0;
    float w = 1.0f;
    for (int a = 0; a < D; ++a) {
      const bool up = (corner >> a) & 1;
      offset += up ? taps[a].upper : taps[a].lower;
      w *= up ? taps[a].fraction : 1.0f - taps[a].fraction;
    }
    r.offset[corner] = offset;
    r.weight[corner] = w;
  }
  // Blending two time samples of correlation c with weights 1 - f and f keeps only
  // (1 - f)^2 + f^2 + 2 f (1 - f) c of their variance (0.87 half-way for this tile): restore it, so
  // the eddies' energy does not pulse as the noise time moves from sample to sample.
  const float f = time.fraction;
  const float gain = 1.0f / std::sqrt((1.0f - f) * (1.0f - f) + f * f + 2.0f * f * (1.0f - f) * adjacentCorrelation_);
  for (float& w : r.weight) w *= gain;
  return r;
}

template <int D>
void curlOfNodalPotential(const GridSpec<D>& spec, const std::vector<Vecf<3>>& psi, MacGrid<D>& u) {
  const IVec<D> nodes = spec.res + IVec<D>::Ones();
  const float inv = static_cast<float>(1.0 / spec.dx);
  if constexpr (D == 2) {
    // u_x on the x-face (i, j + 1/2) = d psi / dy; u_y on (i + 1/2, j) = -d psi / dx.
    const std::size_t sy = static_cast<std::size_t>(nodes[0]);
    auto& ux = u.component(0);
    parallelForCells<2>(ux.size(), [&](const IVec2& f, std::size_t lin) {
      const std::size_t n = static_cast<std::size_t>(f.y()) * sy + f.x();
      ux[lin] = (psi[n + sy][0] - psi[n][0]) * inv;
    });
    auto& uy = u.component(1);
    parallelForCells<2>(uy.size(), [&](const IVec2& f, std::size_t lin) {
      const std::size_t n = static_cast<std::size_t>(f.y()) * sy + f.x();
      uy[lin] = -(psi[n + 1][0] - psi[n][0]) * inv;
    });
  } else {
    // psi_c on the c-edges is the mean of the edge's two nodes; each face's flux is the
    // circulation of psi round its four edges: u_a = d psi_c / d x_b - d psi_b / d x_c, with
    // (a, b, c) cyclic. Written out with the node strides s_b, s_c from the face's lower node n:
    // u_a = [psi_c(n+s_b) + psi_c(n+s_b+s_c) - psi_c(n) - psi_c(n+s_c)
    //        - psi_b(n+s_c) - psi_b(n+s_c+s_b) + psi_b(n) + psi_b(n+s_b)] / (2 h).
    const std::size_t stride[3] = {1, static_cast<std::size_t>(nodes[0]),
                                   static_cast<std::size_t>(nodes[0]) * static_cast<std::size_t>(nodes[1])};
    const float half = 0.5f * inv;
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      const std::size_t sb = stride[b], sc = stride[c];
      auto& ua = u.component(a);
      parallelForCells<3>(ua.size(), [&](const IVec3& f, std::size_t lin) {
        const std::size_t n = static_cast<std::size_t>(f.z()) * stride[2] + static_cast<std::size_t>(f.y()) * stride[1] + f.x();
        const float dc = psi[n + sb][c] + psi[n + sb + sc][c] - psi[n][c] - psi[n + sc][c];
        const float db = psi[n + sc][b] + psi[n + sc + sb][b] - psi[n][b] - psi[n + sb][b];
        ua[lin] = (dc - db) * half;
      });
    }
  }
}

template class NoiseTile<2>;
template class NoiseTile<3>;
template void curlOfNodalPotential<2>(const GridSpec<2>&, const std::vector<Vecf<3>>&, MacGrid<2>&);
template void curlOfNodalPotential<3>(const GridSpec<3>&, const std::vector<Vecf<3>>&, MacGrid<3>&);

}  // namespace msim::turbulence
