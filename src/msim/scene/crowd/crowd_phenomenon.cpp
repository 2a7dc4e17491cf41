#include "msim/scene/crowd/crowd_phenomenon.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"
#include "msim/crowd/fundamental_diagram.hpp"
#include "msim/crowd/measurement_line.hpp"
#include "msim/crowd/metric_plots.hpp"
#include "msim/crowd/metrics_json.hpp"
#include "msim/crowd/metrics.hpp"
#include "msim/crowd/stress/turbulence_metrics.hpp"
#include "msim/crowd/voronoi_density.hpp"
#include "msim/io/atomic_file.hpp"
#include "msim/io/csv.hpp"
#include "msim/io/png.hpp"
#include "msim/io/vdb.hpp"
#include "msim/render/floor_plan.hpp"
#include "msim/render/plot.hpp"
#include "msim/scene/crowd/crowd_scene_keys.hpp"
#include "msim/scene/phenomenon_support.hpp"
#include "msim/scene/scene_file.hpp"

namespace msim::scene {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using crowd::Vec2f;

constexpr const char* kAgentPoints = "agents";
constexpr const char* kStatePoints = "crowd_state";
constexpr double kFdBinWidth = 0.25;  // [1/m^2]
// Float point attributes hold integers exactly up to 2^24.
constexpr double kMaxExactInteger = 16777216.0;
constexpr std::size_t kScatterPerFrame = 500, kScatterTotal = 50000;

class CrowdPhenomenon final : public Phenomenon {
 public:
  CrowdPhenomenon(const Scene& scene, StageTimers& timers)
      : source_(scene.file.string()), timers_(timers), setup_(buildCrowdScene(scene)), preview_(previewWidth(scene)) {
    initialIds_ = setup_.agents.id;
    sim_ = std::make_unique<crowd::CrowdSimulation>(setup_.settings, setup_.obstacles, setup_.goals, setup_.planner,
                                                    setup_.agents, setup_.inflows, setup_.scripts, setup_.moving);
    for (const auto& l : setup_.lines) lines_.push_back(crowd::MeasurementLine{l.from, l.to});
    lineCrossings_.assign(lines_.size(), 0);
    lastIds_ = sim_->agents().id;
    lastPositions_ = sim_->agents().position;
    fdBins_ = crowd::binByDensity({}, kFdBinWidth, std::max(kFdBinWidth, 1.25 * rhoMax()));
    measureFrame();
  }

  double stableTimestep() const override {
    const double v = sim_->maxSpeed();
    const double grid = v > 0.0 ? setup_.gridCfl * setup_.settings.grid.dx / v : setup_.maxStep;
    return std::min(setup_.maxStep, grid);
  }

  void step(double dt) override {
    sim_->step(dt, &timers_);
    ++stepsThisFrame_;
    uicIterations_ += sim_->lastStep().uic.innerIterations + sim_->lastStep().uic.outerIterations;
    uicSolveSeconds_ += sim_->lastStep().uic.solveSeconds;
    const crowd::stress::StressStepStats& st = sim_->lastStep().stress;
    stressSolves_ += st.solves;
    stressIterations_ += st.iterations;
    if (st.unconverged > 0 && stressUnconverged_ == 0)
      logger().warn("{}: crowd stress: the friction solve did not converge at step {} (t = {:.4g} s; counted in "
                    "run.json results.stress)", source_, steps_ + 1, sim_->time());
    stressUnconverged_ += st.unconverged;
    ++steps_;
    const crowd::LookaheadStepStats& la = sim_->lastStep().lookahead;
    lookaheadSolves_ += la.solves;
    lookaheadIterations_ += la.iterations;
    blendWeightSum_ += la.meanWeight;
    ScopedStage stage(timers_, "crowd: metrics");
    const crowd::Agents& a = sim_->agents();
    turbulence_.sample(a, dt);
    // Flow through the measurement lines, step by step (crossings between frames would be missed).
    if (!lines_.empty()) {
      for (std::size_t k = 0; k < lines_.size(); ++k)
        lineCrossings_[k] += crowd::countCrossings(lines_[k], lastIds_, lastPositions_, a.id, a.position).net();
      lastIds_ = a.id;
      lastPositions_ = a.position;
    }
  }

  void endFrame() override {
    iterationsPerStep_ = stepsThisFrame_ > 0 ? double(uicIterations_) / stepsThisFrame_ : 0.0;
    solveMsPerStep_ = stepsThisFrame_ > 0 ? 1e3 * uicSolveSeconds_ / stepsThisFrame_ : 0.0;
    // A frame between two refreshes of the far levels keeps the last one's figure.
    if (lookaheadSolves_ > 0) iterationsPerSolve_ = double(lookaheadIterations_) / double(lookaheadSolves_);
    meanBlendWeight_ = stepsThisFrame_ > 0 ? blendWeightSum_ / stepsThisFrame_ : 0.0;
    lookaheadSolves_ = lookaheadIterations_ = 0;
    blendWeightSum_ = 0.0;
    stepsThisFrame_ = 0;
    uicIterations_ = 0;
    uicSolveSeconds_ = 0.0;
    measureFrame();
  }

  void checkFinite(long stepIndex, double time) const override {
    const crowd::Agents& a = sim_->agents();
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!a.position[i].allFinite() || !a.velocity[i].allFinite())
        throw SimulationError(fmt::format("step {} (t = {:.4g} s): agent {} has a non-finite position or velocity",
                                          stepIndex, time, a.id[i]));
  }

  void writeVolume(io::VdbWriter& writer) const override {
    const crowd::Agents& a = sim_->agents();
    io::PointCloud points;
    points.positions.reserve(a.size());
    for (const Vec2f& x : a.position) points.positions.emplace_back(x.x(), x.y(), 0.0f);
    auto attribute = [&](const char* name, auto value) {
      io::PointAttribute attr{name, std::vector<float>(a.size())};
      for (std::size_t i = 0; i < a.size(); ++i) attr.values[i] = static_cast<float>(value(i));
      points.attributes.push_back(std::move(attr));
    };
    if (a.nextId > kMaxExactInteger)
      throw SimulationError(fmt::format("{}: more than 2^24 agents over the run: their ids no longer fit the VDB points",
                                        source_));
    attribute("id", [&](std::size_t i) { return static_cast<double>(a.id[i]); });
    attribute("vx", [&](std::size_t i) { return a.velocity[i].x(); });
    attribute("vy", [&](std::size_t i) { return a.velocity[i].y(); });
    attribute("radius", [&](std::size_t i) { return a.radius[i]; });
    attribute("max_speed", [&](std::size_t i) { return a.maxSpeed[i]; });
    attribute("goal", [&](std::size_t i) { return static_cast<double>(a.goal[i]); });
    attribute("group", [&](std::size_t i) { return static_cast<double>(a.group[i]); });
    attribute("model", [&](std::size_t i) { return static_cast<double>(a.model[i]); });
    writer.addPoints(kAgentPoints, points, std::max(0.5, setup_.settings.grid.dx));
    // Run state that is not per agent, as one point's attributes: what --resume needs.
    io::PointCloud state;
    state.positions.push_back(Vecf<3>::Zero());
    state.attributes.push_back({"next_id", {static_cast<float>(a.nextId)}});
    const crowd::CrowdSimulation& self = *sim_;
    for (std::size_t k = 0; k < self.inflowCredit().size(); ++k)
      state.attributes.push_back({fmt::format("inflow_credit_{}", k), {static_cast<float>(self.inflowCredit()[k])}});
    for (std::size_t s = 0; s < self.scriptProgress().size(); ++s)
      state.attributes.push_back({fmt::format("script_next_{}", s), {static_cast<float>(self.scriptProgress()[s])}});
    writer.addPoints(kStatePoints, state, 1.0);
    writer.addFogVolume("density", sim_->uic().density());
    writer.addFloatGrid("pressure", sim_->uic().pressure());
    writer.addFloatGrid("free_area", sim_->freeArea().fraction());
  }

  void restore(const fs::path& vdbFile, double time, long /*steps*/) override {
    const io::VdbFile saved(vdbFile, io::VdbProvenance::MsimRun);
    const io::PointCloud points = saved.points(kAgentPoints);
    const io::PointCloud state = saved.points(kStatePoints);
    auto attribute = [&](const io::PointCloud& cloud, const std::string& name) -> const std::vector<float>& {
      return savedPointAttribute(cloud, name, vdbFile, source_);
    };
    crowd::Agents agents;
    agents.reserve(points.positions.size());
    const auto& id = attribute(points, "id");
    const auto& vx = attribute(points, "vx");
    const auto& vy = attribute(points, "vy");
    const auto& radius = attribute(points, "radius");
    const auto& speed = attribute(points, "max_speed");
    const auto& goal = attribute(points, "goal");
    const auto& group = attribute(points, "group");
    const auto& model = attribute(points, "model");
    for (std::size_t i = 0; i < points.positions.size(); ++i) {
      crowd::AgentSpec s;
      s.position = Vec2f(points.positions[i].x(), points.positions[i].y());
      s.radius = radius[i];
      s.maxSpeed = speed[i];
      s.goal = static_cast<std::uint32_t>(goal[i]);
      s.group = static_cast<std::uint32_t>(group[i]);
      s.model = static_cast<crowd::AgentModel>(static_cast<int>(model[i]));
      agents.add(s);
      agents.id.back() = static_cast<std::uint64_t>(id[i]);
      agents.velocity.back() = Vec2f(vx[i], vy[i]);
    }
    agents.nextId = static_cast<std::uint64_t>(attribute(state, "next_id").at(0));
    crowd::CrowdSimulation& sim = *sim_;
    sim.mutableAgents() = std::move(agents);
    for (std::size_t k = 0; k < sim.inflowCredit().size(); ++k)
      sim.inflowCredit()[k] = attribute(state, fmt::format("inflow_credit_{}", k)).at(0);
    for (std::size_t s = 0; s < sim.scriptProgress().size(); ++s)
      sim.scriptProgress()[s] = static_cast<std::size_t>(attribute(state, fmt::format("script_next_{}", s)).at(0));
    sim.setTime(time);
    lastIds_ = sim.agents().id;
    lastPositions_ = sim.agents().position;
    measureFrame();
  }

  io::Image preview() const override {
    render::FloorPlan plan = floorPlan();
    const crowd::Agents& a = sim_->agents();
    render::Discs discs;
    discs.centres.reserve(a.size());
    discs.radii.reserve(a.size());
    discs.values.reserve(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      discs.centres.push_back(a.position[i].cast<double>());
      discs.radii.push_back(a.radius[i]);
    }
    if (setup_.colourBy == "speed") {
      plan.valueMax = std::max(1e-6, sim_->maxSpeed());
      for (std::size_t i = 0; i < a.size(); ++i) discs.values.push_back(a.velocity[i].norm());
    } else if (setup_.colourBy == "density") {
      plan.valueMax = rhoMax();
      discs.values.assign(agentDensity_.begin(), agentDensity_.end());
      discs.values.resize(a.size(), 0.0);
    } else if (setup_.colourBy == "pressure") {
      // Helbing's crowd pressure at each agent's cell, yellow from twice the turbulent 0.02 /s^2.
      plan.valueMax = 2.0 * crowd::stress::TurbulenceMetrics::kTurbulentPressure;
      const Grid<float, 2>& pressure = turbulence_.spatialPressure();
      for (std::size_t i = 0; i < a.size(); ++i) discs.values.push_back(pressure[pressure.spec().clampedCellIndex(a.position[i])]);
    } else {
      plan.valueMax = std::max(1.0, static_cast<double>(groupCount() - 1));
      for (std::size_t i = 0; i < a.size(); ++i) discs.values.push_back(a.group[i]);
    }
    std::vector<std::vector<Vec2>> outlines = staticOutlines();
    for (const crowd::Polygon& p : sim_->movingObstaclesNow()) outlines.push_back(p.vertices);
    return render::renderFloorPlan(plan, discs, outlines);
  }

  json statistics() const override {
    const crowd::Agents& a = sim_->agents();
    const crowd::UicStats& u = sim_->lastStep().uic;
    json s = {{"agents", a.size()},
              {"exited_total", sim_->exits().size()},
              {"spawned_total", a.nextId - initialIds_.size()},
              {"evacuated_fraction", evacuatedFraction()},
              {"arrived_fraction", arrivedFraction()},
              {"mean_speed_mps", speed_.mean},
              {"p95_speed_mps", speed_.p95},
              {"max_density_per_m2", maxDensity_},
              {"uic_density_ratio_max", u.maxRatioAfter},
              {"uic_active_cells", u.activeCells},
              {"uic_iterations_per_step", iterationsPerStep_},
              {"uic_solve_ms_per_step", solveMsPerStep_},
              {"nn_agents", nn_.agents},
              {"nn_closer_than_dmin", nn_.closer},
              {"nn_dense_agents", nn_.dense},
              {"nn_dense_ratio_sum", nn_.denseRatioSum},
              {"nn_dense_mean_ratio", nn_.dense > 0 ? nn_.meanDenseRatio() : 0.0},
              {"nn_min_ratio", std::isfinite(nn_.minRatio) ? nn_.minRatio : 0.0},
              {"free_walkers", freeWalkers_.count},
              {"free_walkers_mean_speed_mps", freeWalkers_.meanSpeed},
              {"stalled", stalledNow_ ? 1 : 0},
              // The scene's inconsistency metric (Golas ch. 3.8) over the last metric window.
              {"inconsistency", sim_->lookahead().sceneInconsistency()},
              // The continuum lookahead's ascent (eq. 3.2; the seed: fewer than 10 iterations on
              // average) and the hybrid's mean blend weight w (eq. 3.11; 0 all discrete, 1 all continuum).
              {"lookahead_iterations_per_solve", iterationsPerSolve_},
              {"lookahead_blend_weight", meanBlendWeight_},
              // Helbing's crowd pressure rho Var(v) (Golas eq. 4.13), the variance over 3 x 3 cells and
              // over the last 3 s: turbulent above 0.02 /s^2; the strain-rate magnitude (Fig. 4.11).
              {"pressure_max_per_s2", turbulenceFrame_.pressureMax},
              {"pressure_cells_over_turbulent", turbulenceFrame_.pressureCellsOver},
              {"pressure_temporal_max_per_s2", turbulenceFrame_.temporalPressureMax},
              {"pressure_temporal_mean_per_s2", turbulenceFrame_.temporalPressureMean},
              {"pressure_temporal_cells_over_turbulent", turbulenceFrame_.temporalCellsOver},
              {"strain_rate_max_per_s", turbulenceFrame_.strainRate.max},
              {"strain_rate_mean_per_s", turbulenceFrame_.strainRate.mean},
              {"strain_rate_variation", turbulenceFrame_.strainRate.variation},
              // Helbing's local speed: the magnitude of the 3 x 3 cells' mean velocity, crowd-averaged.
              {"local_speed_mps", turbulenceFrame_.localSpeed},
              // Stop-and-go: agents standing for 1 s or more while those ahead walk.
              {"standstill_agents", turbulenceFrame_.standing},
              {"standstill_episodes_total", turbulenceFrame_.standstillEpisodes}};
    for (std::size_t k = 0; k < setup_.lines.size(); ++k)
      s["line_" + setup_.lines[k].name + "_crossings"] = lineCrossings_[k];
    return s;
  }

  void writeFrameData(const fs::path& runDir, int frame) const override {
    if (!setup_.trajectories) return;
    const fs::path dir = runDir / "trajectories";
    fs::create_directories(dir);
    const crowd::Agents& a = sim_->agents();
    // Each agent's local inconsistency metric (Golas ch. 3.8) over the agents within about R.
    std::vector<crowd::lookahead::DeviationMoment> cells;
    std::vector<float> sigma;
    sim_->lookahead().localInconsistency(a, setup_.settings.orca.neighbourDist, cells, sigma);
    io::CsvWriter csv(dir / fmt::format("frame_{:05d}.csv", frame), {"frame", "id", "x", "y", "vx", "vy", "inconsistency"});
    for (std::size_t i = 0; i < a.size(); ++i)
      csv.addRow({double(frame), double(a.id[i]), a.position[i].x(), a.position[i].y(), a.velocity[i].x(),
                  a.velocity[i].y(), sigma[i]});
    csv.commit();
  }

  json finishRun(const fs::path& runDir, const json& frames) override {
    json results = json::object();
    if (frames.empty()) return results;
    const int lastFrame = frames.back().at("frame").get<int>();
    if (setup_.trajectories) joinTrajectories(runDir, lastFrame);
    // The seed's validation (ch. 4.5.1): nearest-neighbour distances pooled over every frame.
    double agents = 0, closer = 0, dense = 0, ratioSum = 0;
    for (const json& f : frames) {
      agents += f.at("nn_agents").get<double>();
      closer += f.at("nn_closer_than_dmin").get<double>();
      dense += f.at("nn_dense_agents").get<double>();
      ratioSum += f.at("nn_dense_ratio_sum").get<double>();
    }
    results["nearest_neighbour"] = {{"agent_frames", agents},
                                    {"fraction_closer_than_dmin", agents > 0 ? closer / agents : 0.0},
                                    {"dense_agent_frames", dense},
                                    {"dense_mean_distance_over_dmin", dense > 0 ? ratioSum / dense : 0.0},
                                    {"dense_threshold_per_m2", setup_.denseFraction * rhoMax()}};
    results["rho_max_per_m2"] = rhoMax();
    int stalled = 0;
    for (const json& f : frames) stalled += f.value("stalled", 0);
    results["stalled_frames"] = stalled;
    results["planner"] = setup_.plannerName;
    json evacuation = json::object();
    for (double q : {0.5, 0.9, 1.0}) {
      for (const json& f : frames)
        if (!initialIds_.empty() && f.at("evacuated_fraction").get<double>() >= q - 1e-12) {
          evacuation[fmt::format("t{:.0f}_s", 100 * q)] = f.at("time_s").get<double>();
          break;
        }
    }
    results["evacuation"] = evacuation;
    // Golas ch. 3's "simulation duration": when every agent of the start has reached its goal
    // (left through an exit or stands at its goal), and when half and nine tenths had.
    json completion = json::object();
    for (double q : {0.5, 0.9, 1.0})
      for (const json& f : frames)
        if (!initialIds_.empty() && f.value("arrived_fraction", 0.0) >= q - 1e-12) {
          completion[fmt::format("t{:.0f}_s", 100 * q)] = f.at("time_s").get<double>();
          break;
        }
    results["completion"] = completion;
    if (setup_.settings.stress)
      results["stress"] = {{"friction_solves", stressSolves_},
                           {"iterations_per_solve", stressSolves_ > 0 ? double(stressIterations_) / double(stressSolves_) : 0.0},
                           {"unconverged_solves", stressUnconverged_}};
    json flows = json::object();
    const double duration = frames.back().at("time_s").get<double>();
    for (const auto& l : setup_.lines) {
      const double crossings = frames.back().at("line_" + l.name + "_crossings").get<double>();
      flows[l.name] = {{"net_crossings", crossings},
                       {"flow_per_s", crossings / duration},
                       {"specific_flow_per_m_s", crossings / duration / (l.to - l.from).norm()}};
    }
    results["measurement_lines"] = flows;
    writeFundamentalDiagram(runDir / "fundamental_diagram.png");
    results["turbulence"] = writePressureMap(runDir / "pressure_map.png");
    writeTimeSeries(runDir / "time_series.png", frames);
    results["inconsistency"] = writeInconsistency(runDir / "inconsistency.png", frames);
    results["fundamental_diagram"] = crowd::toJson(std::span<const crowd::FdBin>(fdBins_));
    return results;
  }

 private:
  static int previewWidth(const Scene& scene) {
    return std::max(800, scene.resolved.at("outputs").at("preview").at("width").get<int>());
  }
  double rhoMax() const { return setup_.settings.uicSettings.rhoMax; }
  // The top view of the scene's floor at the preview's width, and its fixed obstacles.
  render::FloorPlan floorPlan() const {
    render::FloorPlan plan;
    plan.lo = setup_.settings.lo;
    plan.hi = setup_.settings.hi;
    plan.width = preview_;
    return plan;
  }
  std::vector<std::vector<Vec2>> staticOutlines() const {
    std::vector<std::vector<Vec2>> outlines;
    for (const crowd::Polygon& p : setup_.obstacles) outlines.push_back(p.vertices);
    return outlines;
  }
  std::size_t groupCount() const { return std::max<std::size_t>(1, setup_.groupCount); }
  double evacuatedFraction() const {
    if (initialIds_.empty()) return 0.0;
    std::size_t initialExited = 0;
    for (const auto& e : sim_->exits())
      if (std::binary_search(initialIds_.begin(), initialIds_.end(), e.agentId)) ++initialExited;
    return double(initialExited) / double(initialIds_.size());
  }

  // The agents of the start that have arrived: left through an exit, or standing at their goal.
  double arrivedFraction() const {
    if (initialIds_.empty()) return 0.0;
    const crowd::Agents& a = sim_->agents();
    const auto& goals = sim_->goals();
    std::size_t standing = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a.model[i] != crowd::AgentModel::Scripted && std::binary_search(initialIds_.begin(), initialIds_.end(), a.id[i]) &&
          goals[a.goal[i]].reached(a.position[i].cast<double>()))
        ++standing;
    return evacuatedFraction() + double(standing) / double(initialIds_.size());
  }

  // Frame metrics, measured once per frame (every step would cost a Voronoi diagram per step).
  // A crowd that stands still with room ahead has stalled: warn once (the frames are counted in
  // run.json). Free walkers are those that want to walk and have fewer than 1 other per m^2 ahead
  // (CrowdSimulation::freeWalkers); a stall needs at least 5 of them and 1% of the crowd.
  void checkStall() {
    static constexpr double kStalledSpeed = 0.2;  // [m/s]
    freeWalkers_ = sim_->freeWalkers();
    const std::size_t enough = std::max<std::size_t>(5, sim_->agents().size() / 100);
    stalledNow_ = sim_->time() > 0.0 && freeWalkers_.count >= enough && freeWalkers_.meanSpeed < kStalledSpeed;
    if (stalledNow_ && !warnedStall_) {
      warnedStall_ = true;
      logger().warn("{}: the crowd stalls at t = {:.4g} s: {} agents with free space ahead walk at {:.2g} m/s on average "
                    "(below {} m/s); check crowd.uic.cell_size against the agents' diameter, and goals that cannot "
                    "be reached (stalled frames are counted in run.json)",
                    source_, sim_->time(), freeWalkers_.count, freeWalkers_.meanSpeed, kStalledSpeed);
    }
  }

  void measureFrame() {
    ScopedStage stage(timers_, "crowd: metrics");
    const crowd::Agents& a = sim_->agents();
    speed_ = crowd::speedStats(a.velocity);
    // Frame times are multiples of the frame interval: the tolerance keeps round-off from
    // leaving out the frame at summaries_from itself.
    turbulenceFrame_ = turbulence_.measure(a, sim_->time() >= setup_.summariesFrom - 1e-9);
    checkStall();
    agentDensity_.clear();
    nn_ = crowd::NearestNeighbourFrame{};
    maxDensity_ = 0.0;
    if (a.empty()) return;
    crowd::VoronoiOptions vo;
    vo.cutoffRadius = 2.0 * setup_.dMin;
    vo.domainLo = setup_.settings.lo;
    vo.domainHi = setup_.settings.hi;
    agentDensity_ = crowd::voronoiDensity(crowd::voronoiCells(a.position, vo));
    for (double d : agentDensity_) maxDensity_ = std::max(maxDensity_, d);
    const crowd::NearestNeighbours nn = crowd::nearestNeighbours(a.position, a.radius, 2.0 * setup_.dMin);
    crowd::NearestNeighbourOptions no;
    no.rhoMax = rhoMax();
    no.denseFraction = setup_.denseFraction;
    nn_ = crowd::nearestNeighbourFrame(nn, agentDensity_, no);
    // Fundamental diagram samples of the moving (non-scripted) agents.
    std::vector<crowd::FdSample> samples;
    samples.reserve(a.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a.model[i] != crowd::AgentModel::Scripted) samples.push_back({agentDensity_[i], a.velocity[i].norm()});
    addToBins(samples);
    // A bounded scatter for the plot: at most kScatterPerFrame evenly strided samples per frame.
    const std::size_t stride = std::max<std::size_t>(1, samples.size() / kScatterPerFrame);
    for (std::size_t i = 0; i < samples.size() && fdScatter_.size() < kScatterTotal; i += stride)
      fdScatter_.push_back(samples[i]);
  }

  void addToBins(const std::vector<crowd::FdSample>& samples) {
    const auto fresh = crowd::binByDensity(samples, kFdBinWidth, fdBins_.back().densityHi);
    for (std::size_t b = 0; b < fdBins_.size(); ++b) {
      // Pool means and variances (Chan et al.) of the old and the new samples of the bin.
      auto& o = fdBins_[b];
      const auto& n = fresh[b];
      if (n.count == 0) continue;
      const double na = double(o.count), nb = double(n.count), total = na + nb;
      const double m2a = o.count > 1 ? o.stdSpeed * o.stdSpeed * (na - 1) : 0.0;
      const double m2b = n.count > 1 ? n.stdSpeed * n.stdSpeed * (nb - 1) : 0.0;
      const double delta = n.meanSpeed - o.meanSpeed;
      const double m2 = m2a + m2b + delta * delta * na * nb / total;
      o.meanSpeed += delta * nb / total;
      o.meanDensity += (n.meanDensity - o.meanDensity) * nb / total;
      o.count += n.count;
      o.stdSpeed = o.count > 1 ? std::sqrt(m2 / (total - 1)) : 0.0;
    }
  }

  // trajectories.csv from the per-frame parts in trajectories/, which stay (like vdb/ and png/) so
  // that a run extended with --resume can join all its frames again.
  void joinTrajectories(const fs::path& runDir, int lastFrame) const {
    const fs::path dir = runDir / "trajectories";
    io::writeFileAtomically(runDir / "trajectories.csv", [&](const fs::path& tmp) {
      std::ofstream out(tmp, std::ios::binary);
      out << "frame,id,x,y,vx,vy,inconsistency\n";
      for (int f = 1; f <= lastFrame; ++f) {
        std::ifstream in(dir / fmt::format("frame_{:05d}.csv", f), std::ios::binary);
        if (!in) throw std::runtime_error(fmt::format("trajectory part of frame {} is missing in {}", f, dir.string()));
        std::string header;
        std::getline(in, header);
        // A frame with no agents (everyone has left) has only the header; inserting an empty
        // buffer would set the stream's failbit.
        if (in.peek() != std::char_traits<char>::eof()) out << in.rdbuf();
      }
      if (!out) throw std::runtime_error("writing trajectories.csv failed");
    });
  }

  // Each cell's largest crowd pressure over time during the run on the floor plan, yellow from
  // twice the turbulent 0.02 /s^2 (cells nobody stood in left as floor); its figures for run.json.
  json writePressureMap(const fs::path& file) const {
    using crowd::stress::TurbulenceMetrics;
    const Grid<float, 2>& peak = turbulence_.peakTemporalPressure();
    render::FloorPlan plan = floorPlan();
    plan.valueMax = 2.0 * TurbulenceMetrics::kTurbulentPressure;
    const render::CellField field{peak.spec(), std::span<const float>(peak.data())};
    io::writePng(file, render::renderFloorPlan(plan, render::Discs{}, staticOutlines(), &field));
    const crowd::stress::PressureSummary summary =
        crowd::stress::summarizePressure(peak, TurbulenceMetrics::kTurbulentPressure);
    // Where the largest temporal pressure of the run occurred (the seed's Love Parade: where the
    // inflow meets the counter-flow), and the frames' samples of the crowd's cells by density.
    const std::size_t peakCell = static_cast<std::size_t>(std::max_element(peak.data().begin(), peak.data().end()) - peak.data().begin());
    const Vec2 peakAt = peak.position(peak.coord(peakCell));
    return {{"pressure_temporal_peak_per_s2", summary.max},
            {"peak_at_m", {peakAt.x(), peakAt.y()}},
            {"cells_ever_turbulent", summary.cellsOver},
            {"window_s", TurbulenceMetrics::kWindowSeconds},
            {"summaries_from_s", setup_.summariesFrom},
            {"by_density", crowd::toJson(turbulence_.samplesByDensity())}};
  }

  void writeFundamentalDiagram(const fs::path& file) const {
    io::writePng(file, render::renderPlot(crowd::speedDensityPlot(fdScatter_, fdBins_)));
  }

  // A per-frame statistic over the run: the frames' times and values of `key`.
  static std::pair<std::vector<double>, std::vector<double>> series(const json& frames, const char* key) {
    std::pair<std::vector<double>, std::vector<double>> out;
    for (const json& f : frames) {
      out.first.push_back(f.at("time_s").get<double>());
      out.second.push_back(f.at(key).get<double>());
    }
    return out;
  }

  void writeTimeSeries(const fs::path& file, const json& frames) const {
    const auto [t, n] = series(frames, "agents");
    io::writePng(file, render::renderPlot(crowd::timeSeriesPlot("agents in the scene", "agents", t, n)));
  }

  // The scene's inconsistency metric over the run (Golas ch. 3.8): its mean and largest frame
  // value, and the unit of the metric mode; and its course as a plot.
  json writeInconsistency(const fs::path& file, const json& frames) const {
    const auto [t, sigma] = series(frames, "inconsistency");
    const bool trace = setup_.settings.lookahead.metricMode == crowd::lookahead::MetricMode::Trace;
    const std::string unit = trace ? "m^2/s^4" : "m/s^2";
    io::writePng(file, render::renderPlot(crowd::timeSeriesPlot("inconsistency metric of the crowd", "sigma (" + unit + ")", t, sigma)));
    double sum = 0.0, largest = 0.0;
    for (const double x : sigma) {
      sum += x;
      largest = std::max(largest, x);
    }
    return {{"mean", sigma.empty() ? 0.0 : sum / static_cast<double>(sigma.size())}, {"max", largest}, {"unit", unit}};
  }

  std::string source_;
  StageTimers& timers_;
  CrowdSceneSetup setup_;
  int preview_ = 800;
  std::unique_ptr<crowd::CrowdSimulation> sim_;
  std::vector<std::uint64_t> initialIds_;
  std::vector<crowd::MeasurementLine> lines_;
  std::vector<long long> lineCrossings_;  // net, since the start
  std::vector<std::uint64_t> lastIds_;
  std::vector<Vec2f> lastPositions_;
  std::vector<crowd::FdBin> fdBins_;
  std::vector<crowd::FdSample> fdScatter_;
  crowd::SpeedStats speed_;
  std::vector<double> agentDensity_;
  crowd::NearestNeighbourFrame nn_;
  double maxDensity_ = 0.0;
  int stepsThisFrame_ = 0;      // steps of the frame being simulated
  long uicIterations_ = 0;      // QP iterations of those steps
  double uicSolveSeconds_ = 0.0;  // QP solve time of those steps (Fig. 4.10)
  double iterationsPerStep_ = 0.0;  // of the last complete frame
  double solveMsPerStep_ = 0.0;     // of the last complete frame
  crowd::stress::TurbulenceMetrics turbulence_{setup_.settings.grid};
  crowd::stress::TurbulenceFrame turbulenceFrame_;
  long steps_ = 0, stressSolves_ = 0, stressIterations_ = 0, stressUnconverged_ = 0;
  std::size_t lookaheadSolves_ = 0, lookaheadIterations_ = 0;  // of the frame being simulated
  double blendWeightSum_ = 0.0;                                 // the steps' mean weights summed
  double iterationsPerSolve_ = 0.0, meanBlendWeight_ = 0.0;     // of the last complete frame
  crowd::CrowdSimulation::FreeWalkers freeWalkers_;
  bool stalledNow_ = false;  // this frame
  bool warnedStall_ = false;
};

void declare(Schema& root) { declareCrowdKeys(root); }

// Grids of the continuum (density, velocity, pressure, free area, scratch of the projection).
double bytesPerCell(int, const json&) { return 400.0; }

std::unique_ptr<Phenomenon> create(const Scene& scene, StageTimers& timers) {
  return std::make_unique<CrowdPhenomenon>(scene, timers);
}

}  // namespace

PhenomenonType crowdPhenomenonType() {
  return {"crowd", "dense crowds: agents with the unilateral incompressibility constraint (Narain 2011, ch. 4)", declare,
          bytesPerCell, create};
}

}  // namespace msim::scene
