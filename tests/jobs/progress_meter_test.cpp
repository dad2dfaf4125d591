// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/progress_meter.h"

#include <gtest/gtest.h>

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "ao/jobs/render.h"
#include "support/run.h"

namespace ao {
namespace {

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// A 20-second stage in a log, on an injected clock: a line every 5 seconds (the default interval),
// each with the percentage, the time elapsed and the time left.
TEST(ProgressMeter, LogWritesALineEveryIntervalOfATwentySecondStage) {
  double t = 0;
  std::string log;
  ProgressMeter meter("raytraced", ProgressMeter::Style::Log, [&](const std::string& s) { log += s; }, 5.0, [&] { return t; });
  const std::size_t total = 2000;
  for (std::size_t done = 1; done <= total; ++done) {
    t = 20.0 * static_cast<double>(done) / static_cast<double>(total);
    meter.update(done, total);
  }
  meter.close();
  EXPECT_EQ(count(log, "\n"), 4u) << log;  // at 5, 10, 15 and 20 s
  EXPECT_NE(log.find("raytraced: 25% of 2000 units, 5.0 s elapsed, ~15 s left\n"), std::string::npos) << log;
  EXPECT_NE(log.find("raytraced: 50% of 2000 units, 10.0 s elapsed, ~10 s left\n"), std::string::npos) << log;
  EXPECT_EQ(log.find('\r'), std::string::npos) << "no terminal control in a log";
}

// A stage shorter than the interval leaves the log silent; a bar waits a second, then redraws in
// place and is erased at the end.
TEST(ProgressMeter, QuickStagesAreSilentAndABarErasesItself) {
  double t = 0;
  std::string log, bar;
  ProgressMeter quiet("G-buffer", ProgressMeter::Style::Log, [&](const std::string& s) { log += s; }, 5.0, [&] { return t; });
  ProgressMeter drawn("G-buffer", ProgressMeter::Style::Bar, [&](const std::string& s) { bar += s; }, 5.0, [&] { return t; });
  for (int i = 1; i <= 40; ++i) {
    t = 0.1 * i;
    quiet.update(static_cast<std::size_t>(i), 40);
    drawn.update(static_cast<std::size_t>(i), 40);
  }
  quiet.close();
  drawn.close();
  EXPECT_TRUE(log.empty()) << log;
  EXPECT_EQ(bar.rfind("\r\033[K"), bar.size() - 4) << "erased at the end";
  EXPECT_NE(bar.find("G-buffer [##########"), std::string::npos) << bar;
  EXPECT_EQ(bar.find('\n'), std::string::npos);
}

TEST(ProgressMeter, RemainingTimeIsTheRateSoFarTimesTheUnitsLeft) {
  EXPECT_DOUBLE_EQ(remaining_seconds(10.0, 500, 1000), 10.0);
  EXPECT_DOUBLE_EQ(remaining_seconds(3.0, 250, 1000), 9.0);
  EXPECT_EQ(remaining_seconds(3.0, 0, 1000), 0.0);
  EXPECT_EQ(remaining_seconds(3.0, 1000, 1000), 0.0);
}

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct HalfwayEstimate {
  double estimate = 0;  ///< CPU seconds left, as estimated at 50% of the units
  double left = 0;      ///< CPU seconds that did remain
};

// One real ray-traced render, its remaining time estimated at 50%. The render counts covered
// pixels (not tiles, which include background that costs nothing), so the rate so far predicts the
// rest. Time is the process's CPU time, which other programs on a shared machine do not stretch as
// they stretch wall time.
HalfwayEstimate estimate_at_half_of_a_render() {
  RenderRequest request;
  request.scene.args = {std::string(AO_TEST_MESHES) + "/elephant.off"};
  request.camera.width = 240, request.camera.height = 135;
  // 4096 rays a pixel: long enough that the threads' start and the last tiles' imbalance stay
  // small beside the half that is estimated.
  request.samples = 4096;
  std::mutex mutex;
  double start = 0, at_half = -1, estimate = 0, end = 0;
  JobReporter reporter;
  reporter.stage = [&](const std::string& stage) -> ProgressFn {
    if (stage != "raytraced") return {};
    start = process_cpu_seconds();
    return [&](std::size_t done, std::size_t total) {
      const double now = process_cpu_seconds();
      std::lock_guard lock(mutex);
      if (at_half < 0 && 2 * done >= total) at_half = now, estimate = remaining_seconds(now - start, done, total);
      end = std::max(end, now);
    };
  };
  run_render(request, reporter);
  if (at_half < 0) return {};
  return {estimate, end - at_half};
}

// The estimate at half of a render, against the time that did remain, within 25% (the issue's
// bound). Pixels differ in cost (open sky rays end early), but the tiles of both halves mix open and
// occluded surface. CPU time is still stretched by what shares the cores' caches (a parallel build,
// the other tests of a parallel CTest: one run missed by more than 25% so), so the median of three
// renders is judged: one disturbed render does not decide.
TEST(ProgressMeter, EstimateAtHalfOfARenderIsWithinAQuarterOfTheTimeLeft) {
  std::vector<double> ratios;
  std::string runs;
  for (int i = 0; i < 3; ++i) {
    const HalfwayEstimate e = estimate_at_half_of_a_render();
    ASSERT_GT(e.left, 0.0) << "the render reported its progress";
    ratios.push_back(e.estimate / e.left);
    char run[80];
    std::snprintf(run, sizeof run, " %.3f s for %.3f s;", e.estimate, e.left);
    runs += run;
  }
  std::sort(ratios.begin(), ratios.end());
  EXPECT_NEAR(ratios[1], 1.0, 0.25) << "estimated, remained (CPU):" << runs;
}

// `ao render` with stderr in a file writes progress lines (here every 0.05 s: the job is short).
// 4096 rays a pixel: about 0.6 s on two cores, a dozen intervals (at 512 the tracer finished within
// two or three, and the test missed its three lines under CI and on a quiet machine alike).
TEST(ProgressMeter, RenderWithStderrInAFileLeavesProgressLines) {
  test::TempDir dir;
  const std::string mesh = std::string(AO_TEST_MESHES) + "/elephant.off";
  const test::RunResult r = test::run_ao_under("env AO_PROGRESS_SECONDS=0.05", "render " + mesh + " --width 320 --height 180 --spp 4096 -o v.png", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GE(count(r.err, "% of "), 3u) << r.err;
  EXPECT_GE(count(r.err, " s left\n"), 3u) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "no bar in a file";
}

}  // namespace
}  // namespace ao
