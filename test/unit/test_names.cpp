#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

namespace stc {

TEST(Names, RoundTripAndRejectUnknownNamingTheField) {
  for (const char* n : {"round_robin", "sequential", "perceptual_sequential", "priority_queues"}) {
    EXPECT_STREQ(toString(parseScheduler(n)), n);
  }
  EXPECT_EQ(parseUnresolvedPolicy("reject"), UnresolvedPolicy::Reject);
  EXPECT_EQ(parseSphereFit("paper"), SphereFit::Paper);
  EXPECT_EQ(parseBoxMode("dynamic"), BoxMode::Dynamic);
  try {
    parseScheduler("fifo");
    FAIL() << "unknown scheduler accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "scheduler");
    EXPECT_NE(std::string(e.what()).find("fifo"), std::string::npos);
  }
  EXPECT_THROW(parseUnresolvedPolicy(""), InputError);
  EXPECT_THROW(parseSphereFit("loose"), InputError);
  EXPECT_THROW(parseBoxMode("AUTO"), InputError);
}

}  // namespace stc
