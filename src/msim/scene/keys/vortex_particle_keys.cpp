#include "msim/scene/keys/vortex_particle_keys.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"

namespace msim::scene {

using nlohmann::json;

namespace {

// Smoke names its up axis; a liquid's is against gravity's largest component (y without gravity).
int upAxis(const json& phenomenon, int dimensions) {
  if (phenomenon.contains("up_axis"))
    return std::min(phenomenon.at("up_axis").get<std::string>()[0] - 'x', dimensions - 1);
  int axis = 1;
  if (phenomenon.contains("gravity")) {
    const Vec3 g = paddedVec3(phenomenon.at("gravity"));
    if (g.squaredNorm() > 0.0) g.cwiseAbs().maxCoeff(&axis);
  }
  return std::min(axis, dimensions - 1);
}

}  // namespace

Schema vortexParticleKeys() {
  Schema v = Schema::object(
      "vortex particles (Selle ch. 3.3-3.5): particles carrying vorticity, moved and stretched by the flow, each "
      "adding the force eps_p xi(|x - x_p|) (N_p x omega_p) to the fluid (docs/smoke.md, docs/liquid.md)");
  v.boolean("enabled", false, "seed and carry vortex particles");
  v.string("kernel", "clamped_gaussian",
           "xi: clamped_gaussian (ch. 3.5: exp(-d^2 / 2 r^2) normalised, cut at d = r) or tent (1 - d / r, unit mass)")
      .choices({"clamped_gaussian", "tent"});
  v.number("radius", "m", 0.0, "r_p, the kernel's radius; 0 = 3 cells (the seed uses 3-4 cells)").min(0.0);
  v.number("strength", "m^5/s", 1e-5,
           "eps_p: the force's scale (the seed gives none; eps_p |omega_p| xi(0) is the peak acceleration)")
      .min(0.0);
  v.number("magnitude", "1/s", 1.0, "|omega_p| of random, azimuthal and vertical seeding").min(0.0);
  v.string("vorticity", "random",
           "the seeded omega_p: random (uniform direction), azimuthal (tangent to circles about the up axis through "
           "the region's centre: Fig. 3.4's explosion), vertical (up or down at random: Fig. 3.3's river eddies) or "
           "local_flow (the grid's curl at the particle)")
      .choices({"random", "azimuthal", "vertical", "local_flow"});
  v.number("minimum_flow_vorticity", "1/s", 0.0, "local_flow: no particle where |curl u| is at most this").min(0.0);
  v.vector("region_min", "m", {0.0, 0.0, 0.0}, "seeding box, lower corner; with region_max [0, 0, 0]: the whole domain")
      .lengths({2, 3});
  v.vector("region_max", "m", {0.0, 0.0, 0.0}, "seeding box, upper corner").lengths({2, 3});
  v.number("rate", "1/s", 0.0, "particles seeded per second between start and end").min(0.0);
  v.integer("count", 0, "particles seeded at t = 0").min(0);
  v.number("start", "s", 0.0, "seeding starts").min(0.0);
  v.number("end", "s", 1e30, "seeding stops (Fig. 3.4 seeds only while the explosion expands)").min(0.0);
  v.string("in_solids", "delete", "particles that enter an obstacle: delete (Fig. 3.5) or push_out along its normal")
      .choices({"delete", "push_out"});
  v.integer("seed", 1, "random seed of the particles' positions and directions").min(0);
  return v;
}

template <int D>
std::unique_ptr<fluid::VortexLayer<D>> vortexLayer(const Scene& scene, const std::string& phenomenon) {
  const json& p = scene.resolved.at(phenomenon);
  const json& v = p.at("vortex_particles");
  if (!v.at("enabled").get<bool>()) return nullptr;
  const std::string key = phenomenon + ".vortex_particles";
  const GridSpec<D> domain = scene.gridSpec<D>();
  fluid::VortexLayerSettings<D> s;
  s.kernel = v.at("kernel") == "tent" ? fluid::VortexKernel::Tent : fluid::VortexKernel::ClampedGaussian;
  const double radius = v.at("radius").get<double>();
  s.seed.radius = radius > 0.0 ? radius : 3.0 * scene.dx;
  s.seed.strength = v.at("strength").get<double>();
  s.seed.magnitude = v.at("magnitude").get<double>();
  const std::string vorticity = v.at("vorticity").get<std::string>();
  s.seed.vorticity = vorticity == "azimuthal"    ? fluid::SeedVorticity::Azimuthal
                     : vorticity == "vertical"   ? fluid::SeedVorticity::Vertical
                     : vorticity == "local_flow" ? fluid::SeedVorticity::LocalFlow
                                                 : fluid::SeedVorticity::Random;
  s.seed.minimumFlowVorticity = v.at("minimum_flow_vorticity").get<double>();
  s.seed.upAxis = upAxis(p, D);
  const Vec3 lo = paddedVec3(v.at("region_min")), hi = paddedVec3(v.at("region_max"));
  const bool wholeDomain = lo.squaredNorm() == 0.0 && hi.squaredNorm() == 0.0;
  for (int a = 0; a < D; ++a) {
    s.seed.regionMin[a] = wholeDomain ? domain.origin[a] : lo[a];
    s.seed.regionMax[a] = wholeDomain ? domain.origin[a] + domain.res[a] * domain.dx : hi[a];
  }
  s.rate = v.at("rate").get<double>();
  s.initialCount = static_cast<std::size_t>(v.at("count").get<long long>());
  s.start = v.at("start").get<double>();
  s.end = v.at("end").get<double>();
  s.solids = v.at("in_solids") == "push_out" ? fluid::VortexSolidHandling::PushOut : fluid::VortexSolidHandling::Delete;
  s.randomSeed = static_cast<std::uint64_t>(v.at("seed").get<long long>());
  try {
    return std::make_unique<fluid::VortexLayer<D>>(s, domain, key);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", scene.file.string(), e.what()));
  }
}

template <int D>
io::PointCloud vortexParticleCloud(const fluid::VortexParticles<D>& particles) {
  io::PointCloud cloud;
  std::vector<io::PointAttribute> w = {{"wx", {}}, {"wy", {}}, {"wz", {}}};
  for (std::size_t p = 0; p < particles.size(); ++p) {
    Vecf<3> x = Vecf<3>::Zero();
    for (int a = 0; a < D; ++a) x[a] = particles.positions()[p][a];
    cloud.positions.push_back(x);
    const fluid::VortexVector<D>& omega = particles.vorticities()[p];
    Vec3 omega3(0.0, 0.0, omega[0]);  // 2D: omega_z only
    if constexpr (D == 3) omega3 = omega;
    for (int a = 0; a < 3; ++a) w[static_cast<std::size_t>(a)].values.push_back(static_cast<float>(omega3[a]));
  }
  cloud.attributes = std::move(w);
  return cloud;
}

template <int D>
void restoreVortexParticles(const io::VdbFile& saved, const std::string& name, fluid::VortexLayer<D>& layer,
                            const std::string& source) {
  const io::PointCloud cloud = saved.points(name);
  const auto& wx = savedPointAttribute(cloud, "wx", saved.path(), source);
  const auto& wy = savedPointAttribute(cloud, "wy", saved.path(), source);
  const auto& wz = savedPointAttribute(cloud, "wz", saved.path(), source);
  fluid::VortexParticles<D>& particles = layer.particles();
  particles.clear();
  for (std::size_t p = 0; p < cloud.positions.size(); ++p) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = cloud.positions[p][a];
    fluid::VortexVector<D> omega;
    if constexpr (D == 3)
      omega = fluid::VortexVector<D>(wx[p], wy[p], wz[p]);
    else
      omega[0] = wz[p];
    particles.add(x, omega, layer.settings().seed.radius, layer.settings().seed.strength);
  }
}

template std::unique_ptr<fluid::VortexLayer<2>> vortexLayer<2>(const Scene&, const std::string&);
template std::unique_ptr<fluid::VortexLayer<3>> vortexLayer<3>(const Scene&, const std::string&);
template io::PointCloud vortexParticleCloud<2>(const fluid::VortexParticles<2>&);
template io::PointCloud vortexParticleCloud<3>(const fluid::VortexParticles<3>&);
template void restoreVortexParticles<2>(const io::VdbFile&, const std::string&, fluid::VortexLayer<2>&,
                                        const std::string&);
template void restoreVortexParticles<3>(const io::VdbFile&, const std::string&, fluid::VortexLayer<3>&,
                                        const std::string&);

}  // namespace msim::scene
