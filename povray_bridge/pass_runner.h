// SPDX-License-Identifier: MIT
// The povray runs of one image (a still or one animation frame): each pass renders a wrapper
// scene from the scratch folder, in the scene's folder, with the user's options and its own,
// into <name>.exr with its log beside it. --keep copies them all when the image is done.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animation.h"
#include "povray_run.h"
#include "reporter.h"

namespace povray_ssao {

// A povray run under way: what it renders, where its image and log go.
struct RunningPass {
  std::string what;  // "depth pass", for messages
  std::string output, log;
  std::vector<std::string> args;            // POV-Ray's command line, for a restart
  std::unique_ptr<RunningProcess> process;  // null: not started
  int attempts = 1;
  uintmax_t log_start = 0;        // where this run's messages begin in the log
  std::optional<double> seconds;  // its wall-clock seconds, once finished
};

struct PassRunner {
  static constexpr int kStartupAttempts = 4;

  std::string executable;
  std::string scene_folder;
  std::string scene_name;  // the file the wrappers include, in scene_folder
  std::string include_folder;
  std::vector<std::string> user_options;  // --ini and the pass-through options, in order
  const ScratchFolder* scratch = nullptr;
  bool keep = false;
  const AnimationFrame* frame = nullptr;  // an animation's frame: rendered alone (+SF +EF)
  // Each run finishes before the next starts: for scenes that write files as they parse
  // (SceneScan::file_write), which runs at once would read half-written from each other.
  bool one_at_a_time = false;

  // Where POV-Ray writes +O<name>.exr: an animation frame's number goes before the extension.
  std::string output(const std::string& name) const;

  // Starts rendering `wrapper` to output(name); finish() waits for it. One at a time, it has
  // finished when this returns.
  RunningPass start(const std::string& what, const std::string& name, const std::string& wrapper,
                    int width, int height, const std::vector<std::string>& extra) const;

  // Waits for the run (if it has not finished); returns its wall-clock seconds. Throws with
  // POV-Ray's own messages when it failed or wrote no image; POV-Ray's parse error when it could
  // not parse the scene. A run whose worker thread did not start in time (POV-Ray 3.7 gives it a
  // few seconds, which a loaded machine can exceed) rendered nothing: it is started again, up to
  // kStartupAttempts runs in all, each retry noted in the log.
  double finish(RunningPass& pass) const;

  // POV-Ray's parse error as the user needs it: one that POV-Ray reports after the scene's
  // last line (in the wrapper or the include that follows the scene) is a block or directive
  // the scene leaves open, so it is said to be at the end of the scene.
  std::string explain_parse_error(const std::string& error) const;

  // start() and finish().
  double render(const std::string& what, const std::string& name, const std::string& wrapper,
                int width, int height, const std::vector<std::string>& extra) const;

 private:
  // finish()'s wait, with the restarts.
  double wait_for(RunningPass& pass) const;
};

// Copies the scratch folder's files to --keep DIR when it goes out of scope (also on failure).
class KeepFiles {
 public:
  KeepFiles(const ScratchFolder& scratch, std::string target, const Reporter& report)
      : scratch_(scratch), target_(std::move(target)), report_(report) {}
  ~KeepFiles();
  KeepFiles(const KeepFiles&) = delete;
  KeepFiles& operator=(const KeepFiles&) = delete;

 private:
  const ScratchFolder& scratch_;
  std::string target_;
  const Reporter& report_;
};

}  // namespace povray_ssao
