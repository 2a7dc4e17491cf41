#include "msim/granular/granular_particles.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "msim/core/rng.hpp"

namespace msim::granular {

void validate(const GranularMaterial& material, std::size_t index) {
  const std::string name = "granular material " + std::to_string(index);
  // Written as negations so that NaN fails them too.
  if (!(material.density > 0.0) || !std::isfinite(material.density))
    throw std::invalid_argument(name + ": density (rho_max) must be a finite number > 0 kg/m^3, got " +
                                std::to_string(material.density));
  if (!(material.friction >= 0.0 && material.friction <= 2.0))
    throw std::invalid_argument(name + ": friction coefficient must lie in [0, 2], got " +
                                std::to_string(material.friction));
}

void validate(std::span<const GranularMaterial> materials) {
  for (std::size_t i = 0; i < materials.size(); ++i) validate(materials[i], i);
}

void validateParticlesPerCell(double particlesPerCell) {
  if (!(particlesPerCell >= 1.0 && particlesPerCell <= kMaxParticlesPerCell))
    throw std::invalid_argument("granular: particles per cell must lie in [1, " +
                                std::to_string(static_cast<int>(kMaxParticlesPerCell)) + "], got " +
                                std::to_string(particlesPerCell));
}

Eigen::Matrix3d shapeMatrix(const ParticleShape& s) {
  Eigen::Matrix3d a;
  a << s[0], s[3], s[4],  //
      s[3], s[1], s[5],   //
      s[4], s[5], s[2];
  return a;
}

ParticleShape toShape(const Eigen::Matrix3d& a) {
  return {static_cast<float>(a(0, 0)), static_cast<float>(a(1, 1)), static_cast<float>(a(2, 2)),
          static_cast<float>(a(0, 1)), static_cast<float>(a(0, 2)), static_cast<float>(a(1, 2))};
}

void GranularParticles::resize(std::size_t n) {
  position.resize(n, Vecf<3>::Zero());
  velocity.resize(n, Vecf<3>::Zero());
  mass.resize(n, 0.0f);
  shape.resize(n, ParticleShape{});
  material.resize(n, 0);
}

void GranularParticles::reserve(std::size_t n) {
  position.reserve(n);
  velocity.reserve(n);
  mass.reserve(n);
  shape.reserve(n);
  material.reserve(n);
}

std::size_t GranularParticles::append(const Vecf<3>& x, const Vecf<3>& v, float m, const ParticleShape& a,
                                      std::uint16_t materialIndex) {
  position.push_back(x);
  velocity.push_back(v);
  mass.push_back(m);
  shape.push_back(a);
  material.push_back(materialIndex);
  return size() - 1;
}

void GranularParticles::copyFrom(const GranularParticles& source, std::size_t from, std::size_t to) {
  position[to] = source.position[from];
  velocity[to] = source.velocity[from];
  mass[to] = source.mass[from];
  shape[to] = source.shape[from];
  material[to] = source.material[from];
}

std::size_t seedRegion(GranularParticles& particles, const GridSpec<3>& grid, const Vec3& lo, const Vec3& hi,
                       const std::function<bool(const Vec3&)>& inside, std::span<const GranularMaterial> materials,
                       const SeedOptions& options) {
  validate(materials);
  if (options.material >= materials.size())
    throw std::invalid_argument("granular seeding: material index " + std::to_string(options.material) +
                                " outside the table of " + std::to_string(materials.size()) + " materials");
  if (!(options.fillFraction > 0.0 && options.fillFraction <= 1.0))
    throw std::invalid_argument("granular seeding: fill fraction must lie in (0, 1], got " +
                                std::to_string(options.fillFraction));
  if (!lo.allFinite() || !hi.allFinite() || !options.velocity.allFinite())
    throw std::invalid_argument("granular seeding: region corners and velocity must be finite");
  if (!(grid.dx > 0.0)) throw std::invalid_argument("granular seeding: grid spacing must be > 0");
  validateParticlesPerCell(options.particlesPerCell);

  const double h = particleSpacing(grid.dx, options.particlesPerCell);
  const double r = particleRadius(grid.dx, options.particlesPerCell);
  const float mass = static_cast<float>(options.fillFraction * materials[options.material].density * h * h * h);
  const ParticleShape sphere = toShape(r * r * Eigen::Matrix3d::Identity());
  const Vecf<3> velocity = options.velocity.cast<float>();

  // Lattice cubes overlapping the box clipped to the grid; `count` numbers the cubes of the whole grid.
  const Vec3 boxLo = lo.cwiseMax(grid.origin), boxHi = hi.cwiseMin(grid.upper());
  IVec3 first, last, count;
  for (int a = 0; a < 3; ++a) {
    count[a] = static_cast<int>(std::ceil(grid.res[a] * grid.dx / h)) + 1;
    first[a] = std::max(0, static_cast<int>(std::floor((boxLo[a] - grid.origin[a]) / h)));
    last[a] = std::min(count[a], static_cast<int>(std::ceil((boxHi[a] - grid.origin[a]) / h)));
  }
  const Rng base(options.seed);
  const std::size_t before = particles.size();
  IVec3 c;
  for (c[2] = first[2]; c[2] < last[2]; ++c[2])
    for (c[1] = first[1]; c[1] < last[1]; ++c[1])
      for (c[0] = first[0]; c[0] < last[0]; ++c[0]) {
        const std::uint64_t cube =
            static_cast<std::uint64_t>(c[0]) +
            static_cast<std::uint64_t>(count[0]) * (static_cast<std::uint64_t>(c[1]) +
                                                    static_cast<std::uint64_t>(count[1]) * c[2]);
        Rng rng = base.split(cube);
        const Vec3 jitter(rng.uniform(), rng.uniform(), rng.uniform());
        const Vec3 x = grid.origin + (c.cast<double>() + jitter) * h;
        if ((x.array() < boxLo.array()).any() || (x.array() > boxHi.array()).any() || !inside(x)) continue;
        particles.append(x.cast<float>(), velocity, mass, sphere, options.material);
      }
  return particles.size() - before;
}

std::size_t seedBox(GranularParticles& particles, const GridSpec<3>& grid, const Vec3& lo, const Vec3& hi,
                    std::span<const GranularMaterial> materials, const SeedOptions& options) {
  return seedRegion(particles, grid, lo, hi, [](const Vec3&) { return true; }, materials, options);
}

}  // namespace msim::granular
