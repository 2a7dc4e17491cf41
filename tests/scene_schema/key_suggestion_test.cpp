#include "msim/scene/schema/key_suggestion.hpp"

#include <gtest/gtest.h>

namespace msim::scene {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(editDistance("rate", "rate"), 0u);
  EXPECT_EQ(editDistance("rat", "rate"), 1u);
  EXPECT_EQ(editDistance("rates", "rate"), 1u);
  EXPECT_EQ(editDistance("rote", "rate"), 1u);
  EXPECT_EQ(editDistance("rtae", "rate"), 1u);
  EXPECT_EQ(editDistance("", "abc"), 3u);
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
}

TEST(ClosestMatch, PicksNearestPlausibleCandidate) {
  const std::vector<std::string> keys{"radius", "rate", "center"};
  EXPECT_EQ(closestMatch("rat", keys), "rate");
  EXPECT_EQ(closestMatch("raduis", keys), "radius");
  EXPECT_EQ(closestMatch("colour", keys), std::nullopt);
}

}  // namespace
}  // namespace msim::scene
