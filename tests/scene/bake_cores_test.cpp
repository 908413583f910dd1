// rtr-bake --profile: each sample's CPU time over its wall time is the cores busy then; a step's wall time
// with fewer than all threads busy, with at most one, and the core-seconds left idle add up sample by
// sample. (The sampler's clock readings are not tested: they depend on the machine's load.)
#include <gtest/gtest.h>

#include "cores.hpp"

using namespace rtr;

TEST(BakeCores, SamplesAddUpPerStep) {
  CoreUse u{"weld"};
  u.add(0.002, 0.016, 8);   // all 8 busy
  u.add(0.002, 0.0152, 8);  // 7.6: all, within half a core
  u.add(0.002, 0.008, 8);   // 4: not all
  u.add(0.002, 0.002, 8);   // 1: one thread's work
  u.add(0.004, 0.0, 8);     // none: waiting
  u.add(0.002, 0.020, 8);   // 10 (a reader beside the workers): all, none idle
  EXPECT_DOUBLE_EQ(u.wall, 0.014);
  EXPECT_NEAR(u.cpu, 0.0612, 1e-12);
  EXPECT_NEAR(u.notAll, 0.002 + 0.002 + 0.004, 1e-12);
  EXPECT_NEAR(u.oneOrNone, 0.002 + 0.004, 1e-12);
  EXPECT_NEAR(u.idle, 0.0008 + 0.008 + 0.014 + 0.032, 1e-12);
  EXPECT_NEAR(u.cores(), 0.0612 / 0.014, 1e-9);
}

TEST(BakeCores, OneThreadIsAllBusyWhenItRuns) {
  CoreUse u{"parse"};
  u.add(0.002, 0.002, 1);
  u.add(0.002, 0.0009, 1);  // less than half a core: not busy
  EXPECT_NEAR(u.notAll, 0.002, 1e-12);
  EXPECT_NEAR(u.oneOrNone, 0.004, 1e-12);
}

TEST(BakeCores, StepsComeBackInTheOrderFirstMarked) {
  CoreSampler s(2, 0.001);
  s.mark("parse");
  s.mark("parse: pieces");
  s.mark("weld");
  s.mark("parse: pieces");
  const std::vector<CoreUse> use = s.stop();
  ASSERT_EQ(use.size(), 3u);
  EXPECT_EQ(use[0].step, "parse");
  EXPECT_EQ(use[1].step, "parse: pieces");
  EXPECT_EQ(use[2].step, "weld");
  EXPECT_EQ(s.threads(), 2u);
}
