#include "msim/granular/granular_simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/timer.hpp"
#include "msim/granular/particle_advection.hpp"

namespace msim::granular {

namespace {

int dominantAxis(const Vec3& g) {
  int axis = 1;
  for (int a = 0; a < 3; ++a)
    if (std::abs(g[a]) > std::abs(g[axis])) axis = a;
  return axis;
}

// Face-major copies between the solver's double faces and the particles' float MAC grid.
void toMac(const FaceField& f, MacGrid<3>& m) {
  for (int a = 0; a < 3; ++a) {
    std::vector<float>& out = m.component(a).data();
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(f.values[a][i]);
  }
}

// Centre of face-a q in world space.
Vec3 faceCentre(const GridSpec<3>& spec, int a, const IVec3& q) {
  Vec3 x = spec.origin + (q.cast<double>().array() + 0.5).matrix() * spec.dx;
  x[a] -= 0.5 * spec.dx;
  return x;
}

}  // namespace

GranularSimulation::GranularSimulation(GranularSettings settings, std::vector<GranularMaterial> materials)
    : settings_(std::move(settings)),
      materials_(std::move(materials)),
      world_([&] {
        rigid::WorldSettings w;
        w.gravity = settings_.gravity;
        return w;
      }()),
      splitMerge_([&] {  // the radius comes from the grid and the density: both checked first
        if (!(settings_.grid.dx > 0.0) || (settings_.grid.res.array() < 1).any())
          throw std::invalid_argument("granular: the grid needs a positive cell size and at least one cell per axis");
        validateParticlesPerCell(settings_.particlesPerCell);
        return particleRadius(settings_.grid.dx, settings_.particlesPerCell);
      }()) {
  if (materials_.empty()) throw std::invalid_argument("granular: at least one material is needed");
  validate(materials_);
  if (!(settings_.cfl > 0.0)) throw std::invalid_argument("granular: cfl must be > 0");
  if (!(settings_.flipRatio >= 0.0 && settings_.flipRatio <= 1.0))
    throw std::invalid_argument("granular: flip_ratio must lie in [0, 1]");
  if (!(settings_.airResponseTime > 0.0) || !std::isfinite(settings_.airResponseTime))
    throw std::invalid_argument("granular: the air response time must be > 0");
  settings_.stress.upAxis = dominantAxis(settings_.gravity);
  stress_.settings() = settings_.stress;
  world_.addDomainBox(settings_.grid.origin, settings_.grid.upper());
  fields_ = ParticleGridFields(settings_.grid);
  velocityNew_ = MacGrid<3>(settings_.grid);
  displacement_ = MacGrid<3>(settings_.grid);
  wallFaces_ = FaceField(settings_.grid.res, 1.0);
  for (int a = 0; a < 3; ++a) {
    const IVec3 n = wallFaces_.size(a);
    parallelForCells<3>(n, [&](const IVec3& q, std::size_t i) {
      if (q[a] == 0 || q[a] == settings_.grid.res[a]) wallFaces_.values[a][i] = 0.0;
    });
  }
  if (settings_.renderPointsPerParticle > 0) renderPoints_.emplace(settings_.renderPointsPerParticle);
  // No split below 1/256 of a fully packed seeded particle of the lightest material (8 halvings).
  const double seededVolume = std::pow(particleSpacing(settings_.grid.dx, settings_.particlesPerCell), 3);
  double lightest = materials_.front().density;
  for (const GranularMaterial& m : materials_) lightest = std::min(lightest, m.density);
  splitMerge_.setMinimumChildMass(lightest * seededVolume / 256.0);
  // No merge above twice a fully packed seeded particle of its material.
  std::vector<double> maximumMass;
  for (const GranularMaterial& m : materials_) maximumMass.push_back(2.0 * m.density * seededVolume);
  splitMerge_.setMaximumMergedMass(std::move(maximumMass));
}

void GranularSimulation::addStaticSolid(std::shared_ptr<const geometry::Shape<3>> solid) {
  if (!solid) throw std::invalid_argument("granular: null static solid");
  for (int a = 0; a < 3; ++a)
    parallelForCells<3>(wallFaces_.size(a), [&](const IVec3& q, std::size_t i) {
      if (solid->distance(faceCentre(settings_.grid, a, q)) < 0.0) wallFaces_.values[a][i] = 0.0;
    });
  staticSolids_.push_back(std::move(solid));
}

double GranularSimulation::solidDistance(const Vec3& x) const {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& s : staticSolids_) d = std::min(d, s->distance(x));
  for (const rigid::RigidBody& b : world_.bodies())
    d = std::min(d, rigid::signedDistance(b.shape(), b.orientation.conjugate() * (x - b.position)));
  return d;
}

double GranularSimulation::solidDistance(const Vec3& x, double cap, std::span<const double> bodyRadii) const {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& s : staticSolids_) d = std::min(d, s->distance(x));
  const auto& bodies = world_.bodies();
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const rigid::RigidBody& b = bodies[k];
    // The distance to a body is at least that to its bounding sphere.
    if ((x - b.position).norm() - bodyRadii[k] >= std::min(d, cap)) continue;
    d = std::min(d, rigid::signedDistance(b.shape(), b.orientation.conjugate() * (x - b.position)));
  }
  return d;
}

std::vector<double> GranularSimulation::bodyBoundingRadii() const {
  std::vector<double> radii;
  for (const rigid::RigidBody& b : world_.bodies()) radii.push_back(rigid::boundingRadius(b.shape()));
  return radii;
}

std::size_t GranularSimulation::seed(const Vec3& lo, const Vec3& hi, const std::function<bool(const Vec3&)>& inside,
                                     const SeedOptions& options) {
  const GridSpec<3>& g = settings_.grid;
  for (int a = 0; a < 3; ++a)
    if (!(lo[a] < hi[a]) || hi[a] <= g.origin[a] || lo[a] >= g.upper()[a])
      throw std::invalid_argument("granular: a seeded region must have lo < hi and overlap the domain");
  SeedOptions dense = options;
  dense.particlesPerCell = settings_.particlesPerCell;
  // Particles are kept half a particle radius clear of every solid.
  const double clearance = 0.5 * particleRadius(g.dx, settings_.particlesPerCell);
  const std::size_t added = seedRegion(
      particles_, g, lo.cwiseMax(g.origin), hi.cwiseMin(g.upper()),
      [&](const Vec3& x) { return inside(x) && solidDistance(x) > clearance; }, materials_, dense);
  if (added == 0) throw std::invalid_argument("granular: the seeded region lies inside solids or holds no cell");
  if (renderPoints_) renderPoints_->sample(particles_);
  return added;
}

void GranularSimulation::resampleRenderPoints() {
  if (renderPoints_) renderPoints_->sample(particles_);
}

double GranularSimulation::stableTimestep(double maxDt) const {
  const std::size_t n = particles_.size();
  double vmax = parallelMax(n, [&](std::size_t i) { return static_cast<double>(particles_.velocity[i].norm()); });
  for (const rigid::RigidBody& b : world_.bodies())
    if (!b.isStatic()) vmax = std::max(vmax, b.velocity.norm() + b.angularVelocity.norm() * rigid::boundingRadius(b.shape()));
  const double speed = vmax + settings_.gravity.norm() * maxDt;
  return speed > 0.0 ? std::min(maxDt, settings_.cfl * settings_.grid.dx / speed) : maxDt;
}

void GranularSimulation::buildGridState() {
  transfer_.toGrid(particles_, materials_, fields_);
  const GridSpec<3>& g = settings_.grid;
  const double invV = 1.0 / g.cellVolume();
  state_.spec = g;
  const std::size_t cells = g.cellCount();
  state_.phi.resize(cells);
  state_.alpha.resize(cells);
  parallelFor(0, cells, [&](std::size_t i) {
    state_.phi[i] = fields_.volume[i] * invV;
    state_.alpha[i] = fields_.friction[i];
  });
  state_.phiFace.reset(g.res);
  state_.rhoFace.reset(g.res);
  for (int a = 0; a < 3; ++a) {
    const std::vector<float>& volume = fields_.faceVolume.component(a).data();
    const std::vector<float>& mass = fields_.faceMass.component(a).data();
    for (std::size_t i = 0; i < volume.size(); ++i) {
      state_.phiFace.values[a][i] = volume[i] * invV;
      state_.rhoFace.values[a][i] = mass[i] * invV;
    }
  }
  state_.open = wallFaces_;
}

void GranularSimulation::rasterizeBodies(double dt) {
  // The CoupledBody objects and their arrays are reused from step to step (no allocation once
  // the boxes stop growing).
  std::size_t used = 0;
  bodyIndex_.clear();
  if (!settings_.coupleBodies) {
    bodies_.clear();
    return;
  }
  const GridSpec<3>& g = settings_.grid;
  const std::vector<rigid::RigidBody>& bodies = world_.bodies();
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const rigid::RigidBody& b = bodies[k];
    if (b.isStatic()) continue;
    if (used == bodies_.size()) bodies_.emplace_back();
    CoupledBody& c = bodies_[used];
    c.inverseMass = b.inverseMassMatrix();
    rigid::Vec6 gravity = rigid::Vec6::Zero();
    gravity.head<3>() = b.mass() * settings_.gravity;
    c.velocity = b.generalizedVelocity() + dt * c.inverseMass * gravity;
    c.centre = b.position;
    // Covered fraction: the ramp 0.5 - d / dx across the surface cell (geometry/occupancy.hpp),
    // nonzero only within half a cell of the body: over the cells of its bounds grown by a cell.
    const Eigen::AlignedBox3d bounds = rigid::orientedBounds(b.shape(), b.orientation);
    IVec3 lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, static_cast<int>(std::floor((b.position[a] + bounds.min()[a] - g.dx - g.origin[a]) / g.dx)));
      hi[a] = std::min(g.res[a] - 1,
                       static_cast<int>(std::floor((b.position[a] + bounds.max()[a] + g.dx - g.origin[a]) / g.dx)));
    }
    c.cover(g.res, LatticeBox{lo, hi});
    if (c.cells.empty()) continue;
    const Eigen::Quaterniond toBody = b.orientation.conjugate();
    auto distance = [&](const Vec3& p) { return rigid::signedDistance(b.shape(), toBody * (p - b.position)); };
    // Blocks of kBlock^3 cells, a slab of blocks per task. The signed distance is 1-Lipschitz, so a
    // block whose centre is farther from the surface than its cell centres are from it (at most
    // sqrt(3) (kBlock - 1) / 2 cells) plus half a cell lies wholly outside (fraction 0) or inside
    // (1): one distance instead of kBlock^3, and the same fractions.
    constexpr int kBlock = 4;
    const double cull = (std::sqrt(3.0) * 0.5 * (kBlock - 1) + 0.5) * g.dx * (1.0 + 1e-9);
    const int slabs = (hi[2] - lo[2]) / kBlock + 1;
    const bool any = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, slabs), false,
        [&](const tbb::blocked_range<int>& r, bool found) {
          for (int slab = r.begin(); slab != r.end(); ++slab)
            for (int by = lo[1]; by <= hi[1]; by += kBlock)
              for (int bx = lo[0]; bx <= hi[0]; bx += kBlock) {
                const IVec3 first(bx, by, lo[2] + slab * kBlock);
                const IVec3 last = (first + IVec3::Constant(kBlock - 1)).cwiseMin(hi);
                const Vec3 centre = 0.5 * (g.cellCenter(first) + g.cellCenter(last));
                const double dc = distance(centre);
                if (dc >= cull) continue;  // fraction 0, as assigned
                const bool inside = dc <= -cull;
                for (int z = first[2]; z <= last[2]; ++z)
                  for (int y = first[1]; y <= last[1]; ++y)
                    for (int x = first[0]; x <= last[0]; ++x) {
                      const IVec3 q(x, y, z);
                      const double f = inside ? 1.0 : std::clamp(0.5 - distance(g.cellCenter(q)) / g.dx, 0.0, 1.0);
                      c.cellFraction[CoupledBody::local(c.cells, q)] = f;
                      found |= f > 0.0;
                    }
              }
          return found;
        },
        [](bool a, bool b) { return a || b; });
    if (!any) continue;
    // Face fractions, the mean of the two cells (0 beyond the box and the grid).
    for (int a = 0; a < 3; ++a) {
      const LatticeBox faces = c.faces(a);
      tbb::parallel_for(faces.first[2], faces.last[2] + 1, [&](int z) {
        for (int y = faces.first[1]; y <= faces.last[1]; ++y)
          for (int x = faces.first[0]; x <= faces.last[0]; ++x) {
            const IVec3 q(x, y, z);
            IVec3 below = q;
            below[a] -= 1;
            c.faceFraction[a][CoupledBody::local(faces, q)] = 0.5 * (c.cellFractionAt(q) + c.cellFractionAt(below));
          }
      });
    }
    ++used;
    bodyIndex_.push_back(static_cast<int>(k));
  }
  bodies_.resize(used);
}

void GranularSimulation::pushOutOfSolids() {
  if (staticSolids_.empty() && world_.bodies().empty()) return;
  const double h = 0.25 * settings_.grid.dx;
  const std::vector<double> radii = bodyBoundingRadii();
  parallelFor(0, particles_.size(), [&](std::size_t i) {
    const Vec3 x = particles_.position[i].cast<double>();
    if (solidDistance(x, 0.0, radii) >= 0.0) return;
    const double d = solidDistance(x);
    // Out along the distance gradient (central differences), to the surface.
    Vec3 n;
    for (int a = 0; a < 3; ++a) {
      Vec3 e = Vec3::Zero();
      e[a] = h;
      n[a] = solidDistance(x + e) - solidDistance(x - e);
    }
    if (!(n.squaredNorm() > 0.0)) return;
    n.normalize();
    particles_.position[i] = clampIntoDomain(settings_.grid, x - d * n).cast<float>();
    // The velocity into the solid is removed (relative to the body it touches, if moving).
    Vec3 solidVelocity = Vec3::Zero();
    for (const rigid::RigidBody& b : world_.bodies())
      if (rigid::signedDistance(b.shape(), b.orientation.conjugate() * (x - b.position)) <= d + 1e-12)
        solidVelocity = b.velocityAt(x);
    Vec3 v = particles_.velocity[i].cast<double>();
    const double vn = (v - solidVelocity).dot(n);
    if (vn < 0.0) v -= vn * n;
    particles_.velocity[i] = v.cast<float>();
  });
}

void GranularSimulation::removeVelocityAgainstCorrection() {
  // The density correction resolves overlaps the way a contact does, so like a contact (and like
  // the inelastic pressure of eq. 5.9) it also removes the velocity into the overlap: a particle
  // pushed back by dx keeps no velocity against dx relative to the material it is pushed away
  // from, whose velocity is the new grid velocity half a cell behind it along dx. Without this,
  // grains resting on a packed surface (whose cells never read as full under the trilinear splat,
  // so the pressure never holds them) keep falling in velocity while the correction puts them back
  // every step. Relative, because packed material moving as a whole (a falling block, whose
  // seeding's jitter the correction evens out) is not in contact with anything: removing its
  // absolute velocity against dx held the top of a falling block in mid-air. A particle already
  // moving along dx is not moving into the overlap and is left alone: a contact only stops motion
  // into it. (Given the velocity of a faster pusher instead, light grains beside a resting body in
  // granular_explosion were kept moving at 1.5 m/s long after the sand had settled.)
  const double reach = 0.5 * settings_.grid.dx;
  parallelFor(0, particles_.size(), [&](std::size_t i) {
    const Vec3& d = correctionAt_[i];
    const double d2 = d.squaredNorm();
    const Vec3 v = particles_.velocity[i].cast<double>();
    if (!(d2 > 0.0) || v.dot(d) >= 0.0) return;
    const Vec3 x = particles_.position[i].cast<double>();
    const Vec3 behind = sampleLinear<3>(velocityNew_, clampIntoDomain(settings_.grid, x - (reach / std::sqrt(d2)) * d));
    const double vd = (v - behind).dot(d);
    if (vd < 0.0) particles_.velocity[i] = (v - (vd / d2) * d).cast<float>();
  });
}

void GranularSimulation::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("granular: the time step must be positive");
  times_ = {};
  const auto stepStart = std::chrono::steady_clock::now();
  {
    ScopedTimer t(times_.transfer);
    buildGridState();
    rasterizeBodies(dt);
  }
  std::vector<const CoupledBody*> coupled;
  for (const CoupledBody& b : bodies_) coupled.push_back(&b);
  {
    ScopedTimer t(times_.correction);
    const FaceField& dx = stress_.correctDensity(state_, coupled);
    toMac(dx, displacement_);
  }
  const bool corrected = stress_.stats().correctionIterations > 0;
  // v* = v^n + dt g on the open faces that hold material (eq. 5.5 without stress); walls at rest.
  FaceField& velocity = predicted_;
  velocity.reset(settings_.grid.res);
  for (int a = 0; a < 3; ++a) {
    const std::vector<float>& v = fields_.velocity.component(a).data();
    for (std::size_t i = 0; i < v.size(); ++i)
      if (state_.open.values[a][i] != 0.0 && state_.rhoFace.values[a][i] > 0.0)
        velocity.values[a][i] = v[i] + dt * settings_.gravity[a];
  }
  if (!winds_.empty()) applyWinds(dt, velocity);
  double solveSeconds = 0.0;
  {
    ScopedTimer t(solveSeconds);
    stress_.solve(state_, dt, velocity, coupled);
  }
  times_.pressure = stress_.stats().pressureSeconds;
  times_.friction = stress_.stats().frictionSeconds;
  times_.assembly = std::max(0.0, solveSeconds - times_.pressure - times_.friction);
  for (int a = 0; a < 3; ++a)
    for (double v : velocity.values[a])
      if (!std::isfinite(v))
        throw std::runtime_error(fmt::format("granular: non-finite grid velocity at t = {:.6g} s (step {:.3g} s)", time_, dt));
  releaseSeparatingWalls(velocity);
  toMac(velocity, velocityNew_);
  {
    ScopedTimer t(times_.bodies);
    for (std::size_t k = 0; k < bodies_.size(); ++k) world_.body(bodyIndex_[k]).applyImpulse(stress_.bodyImpulses()[k]);
    world_.step(dt);
  }
  {
    ScopedTimer t(times_.particles);
    transfer_.toParticles(fields_.velocity, velocityNew_, particles_, settings_.flipRatio);
    // The correction displacement at each particle, for its velocity and its advection.
    if (corrected) {
      sampleCorrection(particles_, displacement_, correctionAt_);
      removeVelocityAgainstCorrection();
    }
    advectParticles(particles_, velocityNew_, dt, corrected ? std::span<const Vec3>(correctionAt_) : std::span<const Vec3>{},
                    renderPoints_ ? &motion_ : nullptr);
    pushOutOfSolids();
    if (settings_.splitMerge) {
      splitMergeStats_ = splitMerge_.apply(particles_);
      // A child of a split lies up to (sqrt3/2) of its parent's semi-axis away from it, which can be
      // beyond a wall; it is put back inside like an advected particle.
      if (splitMergeStats_.splits > 0) {
        const std::span<const SplitMerge::Successors> successors = splitMerge_.successors();
        parallelFor(0, successors.size(), [&](std::size_t i) {
          if (successors[i].count < 2) return;
          for (std::uint32_t c = successors[i].begin; c < successors[i].begin + successors[i].count; ++c)
            particles_.position[c] = clampIntoDomain(settings_.grid, particles_.position[c].cast<double>()).cast<float>();
        });
      }
    }
    if (renderPoints_)
      renderPoints_->carry(motion_, dt, settings_.grid, particles_,
                           settings_.splitMerge ? splitMerge_.successors() : std::span<const SplitMerge::Successors>{});
  }
  time_ += dt;
  times_.step = std::chrono::duration<double>(std::chrono::steady_clock::now() - stepStart).count();
  times_.other = std::max(0.0, times_.step - (times_.transfer + times_.correction + times_.assembly + times_.pressure +
                                              times_.friction + times_.bodies + times_.particles));
}

// The seed closes the domain with ghost cells held full (phi = 1, line 1192), so a wall is a
// unilateral contact like the pressure: it stops flow into it but not material leaving it. The
// solve keeps closed faces at rest, which is right for material pressed against them; where the
// solved flow next to a closed face moves away from it, the face takes that velocity instead, so
// grains thrown against the ceiling fall again and a pile can lift off a wall (with the faces at
// rest they hung there: the particles in the cell beside the wall read mostly its zero velocity).
// The cell between the two faces then translates instead of expanding, so phi <= 1 still holds.
// A closed face with separating flow on both sides (a solid thinner than a cell) stays at rest.
void GranularSimulation::releaseSeparatingWalls(FaceField& velocity) const {
  for (int a = 0; a < 3; ++a) {
    const IVec3 n = wallFaces_.size(a);
    const std::size_t stride = wallFaces_.index(a, IVec3::Unit(a));  // one face along axis a
    const std::vector<double>& open = wallFaces_.values[a];
    const std::vector<double>& rho = state_.rhoFace.values[a];
    std::vector<double>& v = velocity.values[a];
    parallelForCells<3>(n, [&](const IVec3& q, std::size_t i) {
      if (open[i] != 0.0) return;
      // The open neighbour on the side of increasing index separates when its velocity is > 0.
      const bool up = q[a] + 1 < n[a] && open[i + stride] != 0.0 && rho[i + stride] > 0.0 && v[i + stride] > 0.0;
      const bool down = q[a] > 0 && open[i - stride] != 0.0 && rho[i - stride] > 0.0 && v[i - stride] < 0.0;
      if (up != down) v[i] = up ? v[i + stride] : v[i - stride];
    });
  }
}

// Drag towards the winds, dv/dt = (1 - phi) (u_air - v) / tau, integrated exactly over the step
// (stable for any dt / tau) on the faces that hold material, winds at the middle of the step.
void GranularSimulation::applyWinds(double dt, FaceField& velocity) {
  const double t = time_ + 0.5 * dt;
  for (int a = 0; a < 3; ++a) {
    const auto& faces = fields_.velocity.component(a);  // the face layout of component a
    windScratch_.assign(faces.count(), 0.0f);
    for (const auto& w : winds_) w.forEachSample(faces, a, t, [&](std::size_t lin, float u) { windScratch_[lin] += u; });
    std::vector<double>& v = velocity.values[a];
    parallelFor(0, v.size(), [&](std::size_t i) {
      if (state_.open.values[a][i] == 0.0 || state_.rhoFace.values[a][i] <= 0.0) return;
      const double open = 1.0 - std::clamp(state_.phiFace.values[a][i], 0.0, 1.0);
      v[i] += (1.0 - std::exp(-open * dt / settings_.airResponseTime)) * (windScratch_[i] - v[i]);
    }, 4096);
  }
}

double GranularSimulation::totalMass() const {
  return parallelSum(particles_.size(), [&](std::size_t i) { return static_cast<double>(particles_.mass[i]); });
}

Vec3 GranularSimulation::totalMomentum() const {
  Vec3 p;
  for (int a = 0; a < 3; ++a)
    p[a] = parallelSum(particles_.size(), [&](std::size_t i) {
      return static_cast<double>(particles_.mass[i]) * particles_.velocity[i][a];
    });
  return p;
}

}  // namespace msim::granular
