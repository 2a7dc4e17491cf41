#include "msim/crowd/polygon.hpp"

#include <gtest/gtest.h>

#include "msim/core/error.hpp"

namespace msim::crowd {
namespace {

TEST(CrowdPolygon, AreaContainsAndDistanceOfASquare) {
  const Polygon square = rectangle(Vec2(0, 0), Vec2(2, 1));
  EXPECT_DOUBLE_EQ(signedArea(square), 2.0);
  Polygon clockwise = square;
  std::reverse(clockwise.vertices.begin(), clockwise.vertices.end());
  EXPECT_DOUBLE_EQ(signedArea(clockwise), -2.0);
  EXPECT_TRUE(contains(square, Vec2(1.5, 0.5)));
  EXPECT_FALSE(contains(square, Vec2(2.5, 0.5)));
  EXPECT_DOUBLE_EQ(signedDistance(square, Vec2(1.5, 0.75)), -0.25);
  EXPECT_DOUBLE_EQ(signedDistance(square, Vec2(5.0, 5.0)), std::hypot(3.0, 4.0));
}

TEST(CrowdPolygon, RegularPolygonAreaApproachesTheCircle) {
  const Polygon p = regularPolygon(Vec2(1, 2), 2.0, 64);
  const double exact = 0.5 * 64 * 4.0 * std::sin(2 * M_PI / 64);  // n r^2 sin(2 pi / n) / 2
  EXPECT_NEAR(signedArea(p), exact, 1e-12);
}

TEST(CrowdPolygon, SegmentTests) {
  EXPECT_TRUE(segmentsIntersect(Vec2(0, 0), Vec2(1, 1), Vec2(0, 1), Vec2(1, 0)));
  EXPECT_FALSE(segmentsIntersect(Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 1)));
  EXPECT_TRUE(segmentsIntersect(Vec2(0, 0), Vec2(1, 0), Vec2(1, 0), Vec2(2, 5)));  // touching
  const Polygon box = rectangle(Vec2(1, 1), Vec2(2, 2));
  EXPECT_TRUE(segmentHitsPolygon(box, Vec2(0, 1.5), Vec2(3, 1.5)));
  EXPECT_FALSE(segmentHitsPolygon(box, Vec2(0, 0.5), Vec2(3, 0.5)));
  EXPECT_TRUE(segmentHitsPolygon(box, Vec2(1.2, 1.2), Vec2(1.8, 1.8)));  // wholly inside
}

TEST(CrowdPolygon, ValidationNamesTheObjectAndTheEdges) {
  EXPECT_NO_THROW(validateSimple(rectangle(Vec2(0, 0), Vec2(1, 1)), "obstacles[0]"));
  const Polygon bowtie{{Vec2(0, 0), Vec2(2, 2), Vec2(2, 0), Vec2(0, 1)}};
  try {
    validateSimple(bowtie, "obstacles[3]");
    FAIL() << "a bow tie is not simple";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("obstacles[3]"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("edges 0 and 2"), std::string::npos);
  }
  EXPECT_THROW(validateSimple(Polygon{{Vec2(0, 0), Vec2(1, 0)}}, "x"), InputError);
  EXPECT_THROW(validateSimple(Polygon{{Vec2(0, 0), Vec2(1, 0), Vec2(2, 0)}}, "x"), InputError);
}

}  // namespace
}  // namespace msim::crowd
