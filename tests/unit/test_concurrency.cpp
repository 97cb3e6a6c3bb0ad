// SPDX-License-Identifier: MIT
// The thread-safety paragraph of ssao.h, exercised with several std::threads at once: distinct
// jobs run concurrently (each with threads = 2 inside, different variants, sizes and settings)
// and give bit for bit what a single-threaded run gives; ssao_param_info, ssao_variant_info,
// ssao_version, ssao_status_string and ssao_last_error are called from many threads while jobs
// run; each thread sees only its own error message; the progress callback runs on the thread
// that called ssao_job_run. Built and run under ThreadSanitizer too (build-tsan,
// scripts/test.sh), which reports any data race these runs contain.
#include <algorithm>
#include <atomic>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "analytic_scene.h"

using namespace test;

namespace {

// One job's set-up: a variant on a scene of its own size; sizes cross the 128 x 32 tiles.
struct Config {
  const char* variant;
  int width, height;
  const char* resolution;
  const char* denoise;
  bool normals;
  double radius = 1.0;
};

const Config kConfigs[] = {
    {"horizon", 97, 61, "full", "bilateral", true},
    {"hemisphere", 131, 37, "full", "bilateral", true},
    // The sphere at half resolution on this small frame needs a larger radius to darken
    // anything (its points spread evenly to the radius, few near the centre).
    {"sphere", 61, 90, "half", "box4", false, 1.6},
    {"volumetric", 80, 45, "full", "none", false},
    {"unsharp", 129, 33, "full", "bilateral", false},
    {"hemisphere", 64, 64, "half", "bilateral", true},
};

// A floor, a back wall and a box: occlusion in the corners and under the box's edges.
Scene make_scene(const Config& c, Camera& cam) {
  cam.width = c.width;
  cam.height = c.height;
  return ray_cast(cam, {{{{0, -1, 0}, {0, 1, 0}}},
                        {{{0, 0, -9}, {0, 0, 1}}},
                        box({-1.0, -1.0, -7.0}, {0.5, 0.2, -5.5})});
}

struct ProgressCheck {
  std::thread::id caller;
  std::atomic<int> off_thread{0};  // calls seen on another thread
  int calls = 0;
  double last = 0.0;
  bool decreasing = false;
};

int check_progress(void* user, double fraction) {
  auto* p = static_cast<ProgressCheck*>(user);
  if (std::this_thread::get_id() != p->caller) p->off_thread.fetch_add(1);
  if (fraction < p->last) p->decreasing = true;
  p->last = fraction;
  ++p->calls;
  return 1;
}

// Runs one configuration with `threads` and returns its AO; progress is checked when given.
std::vector<float> run_config(const Config& c, int threads, ProgressCheck* progress = nullptr) {
  Camera cam;
  Scene s = make_scene(c, cam);
  Job job;
  job.camera(cam);
  job.set("radius", c.radius);
  job.set("variant", c.variant);
  job.set("resolution", c.resolution);
  job.set("denoise", c.denoise);
  job.set("normal_space", "camera");
  job.set("threads", threads);
  std::vector<float> ao(s.depth.size(), -1.0f);
  job.image("depth", s.depth, s.width, s.height, 1);
  if (c.normals) job.image("normal", s.normal, s.width, s.height, 3);
  job.image("ao", ao, s.width, s.height, 1);
  if (progress) {
    progress->caller = std::this_thread::get_id();
    EXPECT_EQ(ssao_job_set_progress(job.get(), check_progress, progress), SSAO_OK);
  }
  EXPECT_EQ(job.run(), SSAO_OK) << c.variant << ": " << ssao_last_error();
  // A second run of the same job (it keeps its buffers and thread pool between runs).
  if (progress) progress->last = 0.0;  // each run reports from 0 to 1
  std::vector<float> again(ao.size(), -1.0f);
  job.image("ao", again, s.width, s.height, 1);
  EXPECT_EQ(job.run(), SSAO_OK) << c.variant << ": " << ssao_last_error();
  EXPECT_EQ(std::memcmp(ao.data(), again.data(), ao.size() * sizeof(float)), 0)
      << c.variant << ": a second run of the same job differs";
  return ao;
}

// Everything ssao_param_info and ssao_variant_info say, as one comparable string.
std::string describe_tables() {
  std::string out = std::to_string(ssao_version()) + ssao_status_string(SSAO_ERROR_CANCELLED);
  for (size_t i = 0; i < ssao_param_count(); ++i) {
    ssao_param_desc d{};
    if (ssao_param_info(i, &d) != SSAO_OK) return "param_info failed";
    out += std::string(d.name) + d.unit + d.description + std::to_string(d.default_value) +
           std::to_string(d.min_value) + std::to_string(d.max_value) +
           (d.choices ? d.choices : "") + (d.default_string ? d.default_string : "");
  }
  for (size_t i = 0; i < ssao_variant_count(); ++i) {
    ssao_variant_desc v{};
    if (ssao_variant_info(i, &v) != SSAO_OK) return "variant_info failed";
    out += std::string(v.name) + v.description + v.parameters;
  }
  return out;
}

}  // namespace

TEST(Concurrency, JobsOnSeveralThreadsMatchSingleThreadedRuns) {
  constexpr size_t n = std::size(kConfigs);
  std::vector<std::vector<float>> serial(n);
  for (size_t i = 0; i < n; ++i) serial[i] = run_config(kConfigs[i], 1);
  for (size_t i = 0; i < n; ++i) {
    ASSERT_LT(*std::min_element(serial[i].begin(), serial[i].end()), 0.9f)
        << kConfigs[i].variant << ": the scene must have occlusion to compare";
  }

  // Every configuration at once, each on its own thread with two threads inside its job, while
  // other threads read the tables and provoke errors of their own.
  std::vector<std::vector<float>> concurrent(n);
  std::vector<ProgressCheck> progress(n);
  const std::string tables = describe_tables();
  std::atomic<bool> jobs_done{false};
  std::atomic<int> table_mismatches{0}, foreign_errors{0}, table_reads{0};
  std::vector<std::thread> threads;
  for (size_t i = 0; i < n; ++i) {
    threads.emplace_back([&, i] { concurrent[i] = run_config(kConfigs[i], 2, &progress[i]); });
  }
  for (int k = 0; k < 2; ++k) {
    threads.emplace_back([&, k] {
      const std::string name = "no_such_parameter_" + std::to_string(k);
      Job job;
      // At least a few rounds, then as many as the jobs take.
      for (int round = 0; round < 3 || !jobs_done.load(); ++round) {
        if (describe_tables() != tables) table_mismatches.fetch_add(1);
        table_reads.fetch_add(1);
        if (ssao_job_set_float(job.get(), name.c_str(), 1.0) != SSAO_ERROR_INVALID_ARGUMENT ||
            std::string(ssao_last_error()).find(name) == std::string::npos) {
          foreign_errors.fetch_add(1);
        }
      }
    });
  }
  for (size_t i = 0; i < n; ++i) threads[i].join();
  jobs_done = true;
  for (size_t i = n; i < threads.size(); ++i) threads[i].join();

  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(concurrent[i].size(), serial[i].size());
    EXPECT_EQ(std::memcmp(concurrent[i].data(), serial[i].data(), serial[i].size() * sizeof(float)),
              0)
        << kConfigs[i].variant << " " << kConfigs[i].width << "x" << kConfigs[i].height
        << ": a run beside other jobs differs from the single-threaded run";
    EXPECT_GT(progress[i].calls, 2) << kConfigs[i].variant;
    EXPECT_EQ(progress[i].off_thread.load(), 0)
        << kConfigs[i].variant << ": progress called off the thread that runs the job";
    EXPECT_FALSE(progress[i].decreasing) << kConfigs[i].variant;
    EXPECT_EQ(progress[i].last, 1.0) << kConfigs[i].variant;
  }
  EXPECT_GE(table_reads.load(), 6);
  EXPECT_EQ(table_mismatches.load(), 0) << "the tables read differently on another thread";
  EXPECT_EQ(foreign_errors.load(), 0) << "a thread saw another thread's error message";
}

TEST(Concurrency, ErrorMessagesStayOnTheirThread) {
  // Each thread fails with a message naming it, then checks, many times over while the others
  // fail with theirs, that ssao_last_error() still names it; a thread that never fails sees "".
  constexpr int kThreads = 6, kRounds = 200;
  std::atomic<int> wrong{0};
  std::atomic<int> ready{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      ready.fetch_add(1);
      while (ready.load() < kThreads + 1) std::this_thread::yield();
      const std::string mine = "thread_" + std::to_string(t) + "_parameter";
      Job job;
      for (int round = 0; round < kRounds; ++round) {
        if (ssao_job_set_int(job.get(), mine.c_str(), round) != SSAO_ERROR_INVALID_ARGUMENT) {
          wrong.fetch_add(1);
        }
        const std::string seen = ssao_last_error();
        // Successful calls between leave the message alone.
        EXPECT_EQ(ssao_job_set_int(job.get(), "seed", round), SSAO_OK);
        if (seen.find(mine) == std::string::npos || seen != ssao_last_error()) wrong.fetch_add(1);
      }
    });
  }
  std::string quiet_thread_saw = "not run";
  threads.emplace_back([&] {
    ready.fetch_add(1);
    while (ready.load() < kThreads + 1) std::this_thread::yield();
    for (int round = 0; round < kRounds; ++round) {
      quiet_thread_saw = ssao_last_error();
      if (!quiet_thread_saw.empty()) break;
    }
  });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(wrong.load(), 0) << "a thread's last error was not its own";
  EXPECT_EQ(quiet_thread_saw, "") << "a thread that made no call saw an error";
}
