// Measurement lines count exactly the steps that cross them, with sign; evacuation times from
// synthetic removal events.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "msim/crowd/measurement_line.hpp"
#include "msim/crowd/metrics_json.hpp"

#include <nlohmann/json.hpp>

namespace msim::crowd {
namespace {

// The line from (0, 0) to (0, 2): positive crossings go towards +x.
const MeasurementLine kLine{Vec2(0, 0), Vec2(0, 2)};

TEST(MeasurementLine, CountsSignedCrossingsExactly) {
  const std::vector<Vec2f> old = {
      Vec2f(-1, 0.5f),  // crosses to +x: +1
      Vec2f(1, 1),      // crosses to -x: -1
      Vec2f(-1, 3),     // passes above the end b
      Vec2f(-1, 1.5f),  // stays left
      Vec2f(-1, 0),     // through the end a: the line is [a, b), +1
      Vec2f(-1, 2),     // through the end b: not counted
      Vec2f(0, 1),      // from on the line (left side) to the right: +1
      Vec2f(-1, 1),     // onto the line: still the left side, 0
      Vec2f(-0.5f, -1), // diagonal through (0, 0.5): +1
  };
  const std::vector<Vec2f> now = {Vec2f(1, 0.5f), Vec2f(-1, 1),   Vec2f(1, 3), Vec2f(-0.5f, 1.5f), Vec2f(1, 0),
                                  Vec2f(1, 2),    Vec2f(1, 1),    Vec2f(0, 1), Vec2f(0.5f, 2)};
  const LineCrossings c = countCrossings(kLine, old, now);
  EXPECT_EQ(c.positive, 4u);
  EXPECT_EQ(c.negative, 1u);
  EXPECT_EQ(c.net(), 3);
}

TEST(MeasurementLine, MatchesAgentsByIdAcrossSpawnsAndRemovals) {
  // Id 1 was removed, id 4 spawned on the far side: neither counts.
  const std::vector<std::uint64_t> oldIds = {1, 2, 3}, nowIds = {2, 3, 4};
  const std::vector<Vec2f> old = {Vec2f(-1, 1), Vec2f(-1, 1), Vec2f(1, 1)};
  const std::vector<Vec2f> now = {Vec2f(1, 1), Vec2f(-1, 1.5f), Vec2f(1, 1)};
  const LineCrossings c = countCrossings(kLine, oldIds, old, nowIds, now);
  EXPECT_EQ(c.positive, 1u);
  EXPECT_EQ(c.negative, 1u);
  const std::vector<std::uint64_t> unsorted = {3, 2, 4};
  EXPECT_THROW(countCrossings(kLine, oldIds, old, unsorted, now), std::invalid_argument);
}

TEST(MeasurementLine, FlowAndSpecificFlow) {
  FlowMeter meter(kLine);
  const LineFlow step = meter.add({.positive = 3, .negative = 1}, 0.5);
  EXPECT_DOUBLE_EQ(step.flow, 4.0);          // 2 net in 0.5 s
  EXPECT_DOUBLE_EQ(step.specificFlow, 2.0);  // over a 2 m line
  meter.add({.positive = 1, .negative = 0}, 1.5);
  const LineFlow total = meter.total();
  EXPECT_EQ(total.crossings.positive, 4u);
  EXPECT_DOUBLE_EQ(total.duration, 2.0);
  EXPECT_DOUBLE_EQ(total.flow, 1.5);
  EXPECT_DOUBLE_EQ(total.specificFlow, 0.75);
  EXPECT_DOUBLE_EQ(toJson(total)["flow"].get<double>(), 1.5);
  EXPECT_THROW(meter.add({}, 0.0), std::invalid_argument);
  EXPECT_THROW(FlowMeter(MeasurementLine{Vec2(1, 1), Vec2(1, 1)}), std::invalid_argument);
}

TEST(MeasurementEvacuation, TimesFromRemovalEvents) {
  std::vector<std::uint64_t> initial;
  for (std::uint64_t id = 0; id < 10; ++id) initial.push_back(id);
  EvacuationTimer timer(initial);
  for (std::uint64_t id = 0; id < 4; ++id) timer.removed(1.0 + id, id);  // 4 gone by t = 4
  timer.removed(4.5, 100);  // an inflow agent: ignored
  timer.removed(4.6, 3);    // already gone: ignored
  EXPECT_FALSE(timer.times().t50);
  timer.removed(5.0, 4);  // 5 of 10
  ASSERT_TRUE(timer.times().t50);
  EXPECT_DOUBLE_EQ(*timer.times().t50, 5.0);
  for (std::uint64_t id = 5; id < 9; ++id) timer.removed(6.0 + id, id);  // the 9th at t = 14
  ASSERT_TRUE(timer.times().t90);
  EXPECT_DOUBLE_EQ(*timer.times().t90, 14.0);
  EXPECT_FALSE(timer.times().t100);
  EXPECT_TRUE(toJson(timer.times())["t100"].is_null());
  timer.removed(20.0, 9);
  EXPECT_DOUBLE_EQ(*timer.times().t100, 20.0);
  EXPECT_EQ(timer.times().left, 10u);
  EXPECT_THROW(timer.removed(19.0, 9), std::invalid_argument);
}

TEST(MeasurementEvacuation, ThresholdsRoundUpToWholeAgents) {
  // 3 agents: 50% is 2 of them, 90% is all 3.
  const std::vector<std::uint64_t> initial = {7, 8, 9};
  EvacuationTimer timer(initial);
  timer.removed(1.0, 9);
  EXPECT_FALSE(timer.times().t50);
  timer.removed(2.0, 7);
  EXPECT_DOUBLE_EQ(*timer.times().t50, 2.0);
  EXPECT_FALSE(timer.times().t90);
  timer.removed(3.0, 8);
  EXPECT_DOUBLE_EQ(*timer.times().t90, 3.0);
  EXPECT_DOUBLE_EQ(*timer.times().t100, 3.0);
}

}  // namespace
}  // namespace msim::crowd
