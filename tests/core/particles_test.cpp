// Particles: channels stay aligned through append, resize and removeIf.
#include <gtest/gtest.h>

#include <stdexcept>

#include "msim/core/particles.hpp"

using namespace msim;

TEST(Particles, AppendExtendsEveryChannelWithItsInitialValue) {
  Particles<3> p;
  p.append(Vecf<3>(1, 2, 3));
  p.addScalar("mass", 2.5f);
  p.addVector("velocity", Vecf<3>(0, 0, -1));
  const std::size_t i = p.append(Vecf<3>(4, 5, 6));
  EXPECT_EQ(i, 1u);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p.scalar("mass"), (std::vector<float>{2.5f, 2.5f}));
  EXPECT_EQ(p.vector("velocity")[1], Vecf<3>(0, 0, -1));
  p.resize(5);
  EXPECT_EQ(p.scalar("mass").size(), 5u);
  EXPECT_EQ(p.vector("velocity").size(), 5u);
  EXPECT_EQ(p.scalar("mass")[4], 2.5f);
}

TEST(Particles, RemoveIfCompactsAllChannelsStably) {
  Particles<2> p;
  auto& id = p.addScalar("id");
  p.addVector("velocity");
  for (int k = 0; k < 100; ++k) {
    const std::size_t i = p.append(Vecf<2>(float(k), float(-k)));
    id[i] = float(k);
    p.vector("velocity")[i] = Vecf<2>(float(2 * k), 0);
  }
  // The predicate reads a channel: it must see the pre-removal particle set.
  const std::size_t removed = p.removeIf([&](std::size_t i) { return int(id[i]) % 3 == 0; });
  EXPECT_EQ(removed, 34u);
  ASSERT_EQ(p.size(), 66u);
  float previous = -1.0f;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const float k = p.scalar("id")[i];
    EXPECT_NE(int(k) % 3, 0);
    EXPECT_GT(k, previous);  // order kept
    previous = k;
    EXPECT_EQ(p.positions()[i], Vecf<2>(k, -k));
    EXPECT_EQ(p.vector("velocity")[i], Vecf<2>(2 * k, 0));
  }
  EXPECT_EQ(p.removeIf([](std::size_t) { return false; }), 0u);
  EXPECT_EQ(p.removeIf([](std::size_t) { return true; }), 66u);
  EXPECT_TRUE(p.empty());
  EXPECT_TRUE(p.scalar("id").empty());
}

TEST(Particles, MissingChannelThrowsNamingIt) {
  Particles<3> p;
  p.addScalar("mass");
  EXPECT_TRUE(p.hasScalar("mass"));
  EXPECT_FALSE(p.hasVector("mass"));
  try {
    p.scalar("temperature");
    FAIL() << "expected std::out_of_range";
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("temperature"), std::string::npos);
  }
  EXPECT_THROW(p.vector("mass"), std::out_of_range);
  EXPECT_THROW(p.addVector("mass"), std::invalid_argument);
}

TEST(Particles, ChannelReferencesSurviveAddingChannels) {
  Particles<2> p;
  p.resize(3);
  auto& mass = p.addScalar("mass", 1.0f);
  for (int k = 0; k < 20; ++k) p.addScalar("extra" + std::to_string(k));
  mass[2] = 7.0f;
  EXPECT_EQ(p.scalar("mass")[2], 7.0f);
  EXPECT_EQ(p.scalarNames().size(), 21u);
}
