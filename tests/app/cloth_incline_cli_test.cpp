// Cloth on the seed's incline (Selle ch. 6.5, theta = pi/5, g = 9.8) through the whole cloth
// phenomenon, collision loop included: a cloth lying flat on the slope slides like the seed's
// particle, a = g (sin theta - mu cos theta), and friction above tan theta holds it; the scene of
// Fig. 6.8 (scenes/cloth_incline.json) lands on its lower edge, rolls over it and comes to rest.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "msim/io/ply.hpp"

namespace {

using nlohmann::json;
using namespace msim;

const double kTheta = std::acos(-1.0) / 5.0;
const double kGravity = 9.8;
const Vec3 kDownhill(std::cos(kTheta), -std::sin(kTheta), 0.0);
const Vec3 kNormal(std::sin(kTheta), std::cos(kTheta), 0.0);  // the slope's, as in the scene file
const std::string kInclineScene = std::string(MSIM_SOURCE_DIR) + "/scenes/cloth_incline.json";
const std::string kQuiet = " --set render.enabled=false --set outputs.vdb=false --set outputs.png=false --set outputs.mp4=false";

std::string vec(const Vec3& v) { return fmt::format("[{:.9g},{:.9g},{:.9g}]", v.x(), v.y(), v.z()); }

fs::path runIncline(const std::string& name, const std::string& sets) {
  const fs::path dir = scratch(name);
  const Result r = runMsim("run " + kInclineScene + " -q --out " + (dir / "out").string() + kQuiet + sets);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return dir / "out";
}

std::vector<Vec3> frame(const fs::path& out, int index) {
  return io::readPlyMesh(out / "mesh" / fmt::format("cloth_incline_{:04d}.ply", index)).mesh.vertices;
}

double downhill(const std::vector<Vec3>& vertices) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& x : vertices) sum += x;
  return (sum / static_cast<double>(vertices.size())).dot(kDownhill);
}

// A 0.8 x 0.5 m patch of 16 x 10 quads lying on the slope, 0.5 mm above it, at rest.
std::string flatOnTheSlope(double friction) {
  return " --set 'cloth.patch.origin=" + vec(0.0005 * kNormal + Vec3(0, 0, -0.25)) + "' --set 'cloth.patch.edge_u=" +
         vec(0.8 * kDownhill) + "' --set 'cloth.patch.quads=[16,10]' --set 'cloth.initial_velocity=[0,0,0]'" +
         fmt::format(" --set 'bodies[0].friction={}' --set time.duration=1.0", friction);
}

}  // namespace

TEST(ClothIncline, FlatClothSlidesAtTheCoulombRateAndFrictionAboveTanThetaHoldsIt) {
  // mu = 0.5 < tan(pi/5) = 0.727: the centroid's acceleration along the slope, from second
  // differences of frames 2-24 (16 inner steps of the collision loop each), is the particle's
  // g (sin theta - mu cos theta) = 1.7969 m/s^2; a tolerance of the solve that grew with the
  // cloth's speed lost 5% of it by 2.6 m/s. mu = 0.9: static friction holds the cloth.
  const fs::path sliding = runIncline("cloth_incline_slide", flatOnTheSlope(0.5));
  const double dt = 1.0 / 24.0, expected = kGravity * (std::sin(kTheta) - 0.5 * std::cos(kTheta));
  std::vector<double> s;
  for (int f = 2; f <= 24; ++f) s.push_back(downhill(frame(sliding, f)));
  for (std::size_t k = 1; k + 1 < s.size(); ++k)
    EXPECT_NEAR((s[k + 1] - 2.0 * s[k] + s[k - 1]) / (dt * dt), expected, 0.005 * expected) << "frame " << k + 2;
  const fs::path held = runIncline("cloth_incline_hold", flatOnTheSlope(0.9));
  EXPECT_LT(std::abs(downhill(frame(held, 24)) - downhill(frame(held, 1))), 1e-4);
  EXPECT_LT(readJson(held / "run.json").at("frames").back().at("kinetic_energy_J").get<double>(), 1e-9);
}

TEST(ClothIncline, ThrownClothRollsOverTheEdgeItLandsOnAndComesToRest) {
  // Fig. 6.8 scaled down (24 x 15 quads): the cloth leans 70 degrees from the slope and is thrown
  // at it; its lower edge (vertices i = 24 of each row) lands first, and the upper edge (i = 0)
  // comes over it to lie further down the slope. mu = 0.9 > tan theta: it ends at rest, with no
  // vertex in the slope and no intersecting triangle pair in any frame.
  const fs::path out = runIncline("cloth_incline_roll", " --set 'cloth.patch.quads=[24,15]'");
  const std::vector<Vec3> last = frame(out, 36);
  double upper = 0.0, lower = 0.0;
  for (int j = 0; j <= 15; ++j) {
    upper += last[static_cast<std::size_t>(25 * j)].dot(kDownhill) / 16.0;
    lower += last[static_cast<std::size_t>(25 * j + 24)].dot(kDownhill) / 16.0;
  }
  EXPECT_GT(upper, lower + 0.3) << "the upper edge should lie downhill of the lower one";
  const json frames = readJson(out / "run.json").at("frames");
  for (const json& f : frames) {
    EXPECT_EQ(f.at("self_intersections").get<int>(), 0) << f.dump();
    EXPECT_EQ(f.at("vertices_inside_bodies").get<int>(), 0) << f.dump();
  }
  EXPECT_LT(frames.back().at("kinetic_energy_J").get<double>(), 1e-9);
  EXPECT_LT(std::abs(downhill(last) - downhill(frame(out, 32))), 1e-4) << "at rest for the last 4 frames";
}
