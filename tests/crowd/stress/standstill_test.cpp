// Standstill episodes (Golas ch. 4.4, the seed's check T11): an agent that wants to walk and
// stands for 1 s while the people ahead walk is one episode, counted once however long it stands;
// one that stands in a crowd that has stopped as a whole, or one that has arrived, is not.
#include <gtest/gtest.h>

#include "msim/crowd/stress/standstill.hpp"

using namespace msim;
using namespace msim::crowd;
using namespace msim::crowd::stress;

namespace {

// A file of agents along y = 5 walking east: one standing at x = 4, four ahead at x = 5-8 walking
// at `aheadSpeed`.
Agents file(float aheadSpeed) {
  Agents a;
  for (int k = 0; k < 5; ++k) {
    AgentSpec s;
    s.position = Vec2f(4.0f + k, 5.0f);
    const std::size_t i = a.add(s);
    a.preferredVelocity[i] = Vec2f(1.2f, 0.0f);
    a.velocity[i] = Vec2f(k == 0 ? 0.01f : aheadSpeed, 0.0f);
  }
  return a;
}

}  // namespace

TEST(Standstill, StandingBehindWalkersForASecondIsOneEpisode) {
  const GridSpec<2> grid(Vec2(0.0, 0.0), 0.5, IVec<2>(24, 20));
  StandstillDetector detector(grid);
  Agents a = file(1.0f);
  for (int step = 0; step < 19; ++step) detector.sample(a, 0.05);  // 0.95 s
  EXPECT_EQ(detector.episodes(), 0);
  detector.sample(a, 0.05);  // 1 s
  EXPECT_EQ(detector.episodes(), 1);
  EXPECT_EQ(detector.standing(), 1);
  for (int step = 0; step < 40; ++step) detector.sample(a, 0.05);  // still standing: the same episode
  EXPECT_EQ(detector.episodes(), 1);
  a.velocity[0] = Vec2f(0.5f, 0.0f);  // walks on, then stands again
  detector.sample(a, 0.05);
  EXPECT_EQ(detector.standing(), 0);
  a.velocity[0] = Vec2f(0.0f, 0.0f);
  for (int step = 0; step < 20; ++step) detector.sample(a, 0.05);
  EXPECT_EQ(detector.episodes(), 2);
}

TEST(Standstill, AJammedCrowdOrAnArrivedAgentIsNoEpisode) {
  const GridSpec<2> grid(Vec2(0.0, 0.0), 0.5, IVec<2>(24, 20));
  StandstillDetector jammed(grid);
  Agents all = file(0.01f);  // everyone ahead stands too
  for (int step = 0; step < 60; ++step) jammed.sample(all, 0.05);
  EXPECT_EQ(jammed.episodes(), 0);
  StandstillDetector arrived(grid);
  Agents a = file(1.0f);
  a.preferredVelocity[0] = Vec2f::Zero();  // at its goal: it does not want to walk
  for (int step = 0; step < 60; ++step) arrived.sample(a, 0.05);
  EXPECT_EQ(arrived.episodes(), 0);
}
