// rtr-view --pipeline-stats: every pipeline the renderer made, listed by its shaders, with the driver's
// statistics where the device has VK_KHR_pipeline_executable_properties (lavapipe has not: names only,
// and a note that says why; a GPU run checks the statistics themselves).
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_paths.hpp"

namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct ViewRun {
  int status = -1;
  std::string out;
};

// The small temple on the compute rasteriser and the visibility path: the raster and shade pipelines.
ViewRun view(const std::string& args) {
  ViewRun r;
  r.out = rtr::test::runTool("rtr-view",
                             (rtr::test::assetDir() / "temple.rtrscene").string() +
                                 " --headless --size 160x90 --bench 1 --raster compute --shading-path visibility " + args,
                             &r.status, "RTR_TEXTURE_CACHE=off", false);
  r.status = rtr::test::exitCode(r.status);
  return r;
}

TEST(PipelineStatsTest, ListsTheRasterAndShadePipelinesWithTheDriversStatistics) {
  const ViewRun r = view("--pipeline-stats");
  ASSERT_EQ(r.status, 0) << r.out;
  const size_t at = r.out.find("pipeline statistics: ");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::istringstream in(r.out.substr(at));
  std::string head, line;
  std::getline(in, head);
  const bool statistics = head.find("the driver's names") != std::string::npos;
  if (!statistics) { EXPECT_THAT(head, HasSubstr("no statistics (the device lacks VK_KHR_pipeline_executable_properties)")); }
  // Per pipeline, its statistic lines (four spaces in).
  std::vector<std::pair<std::string, int>> pipelines;
  while (std::getline(in, line)) {
    if (line.rfind("pipeline ", 0) == 0) pipelines.push_back({line.substr(9), 0});
    else if (line.rfind("    ", 0) == 0 && !pipelines.empty()) ++pipelines.back().second;
    else if (line.rfind("  ", 0) != 0) break;
  }
  const std::regex count(R"(pipeline statistics: ([0-9]+) pipelines on )");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(head, m, count)) << head;
  EXPECT_EQ(std::stoul(m[1]), pipelines.size()) << r.out;
  for (const char* wanted : {"raster.comp.spv", "raster_large.comp.spv", "vis_shade.comp.spv"}) {
    int found = 0;
    for (const auto& [name, stats] : pipelines)
      if (name.rfind(wanted, 0) == 0) {
        ++found;
        if (statistics) {
          EXPECT_GT(stats, 0) << name << " has no statistics\n" << r.out;
        } else {
          EXPECT_EQ(stats, 0) << name;
        }
      }
    EXPECT_EQ(found, 1) << wanted << "\n" << r.out;
  }
}

TEST(PipelineStatsTest, NothingWithoutTheFlag) {
  const ViewRun r = view("");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_THAT(r.out, Not(HasSubstr("pipeline ")));
}

}  // namespace
