// SPDX-License-Identifier: MIT
#include "pass_runner.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "tools/error.h"

namespace povray_ssao {

namespace fs = std::filesystem;

std::string PassRunner::output(const std::string& name) const {
  return scratch->file(name + (frame ? frame->digits : "") + ".exr");
}

RunningPass PassRunner::start(const std::string& what, const std::string& name,
                              const std::string& wrapper, int width, int height,
                              const std::vector<std::string>& extra) const {
  RunningPass pass;
  pass.what = what;
  pass.output = output(name);
  pass.log = scratch->file(name + ".log");
  std::vector<std::string> args = user_options;
  if (frame) {
    args.push_back("+SF" + std::to_string(frame->number));
    args.push_back("+EF" + std::to_string(frame->number));
  }
  args.push_back("+I" + scratch->file(wrapper));
  args.push_back("+O" + scratch->file(name + ".exr"));
  args.push_back("+W" + std::to_string(width));
  args.push_back("+H" + std::to_string(height));
  args.push_back("-D");
  args.push_back("-P");
  args.push_back("+FE");
  args.push_back("+L" + scene_folder);
  args.push_back("+L" + include_folder);
  args.insert(args.end(), extra.begin(), extra.end());
  // The log starts with the command, so that a kept log can be rerun by hand.
  if (FILE* file = std::fopen(pass.log.c_str(), "w")) {
    std::fprintf(file, "povray-ssao: %s", executable.c_str());
    for (const std::string& arg : args) std::fprintf(file, " %s", arg.c_str());
    std::fprintf(file, "\n(in %s)\n\n", scene_folder.c_str());
    std::fclose(file);
  }
  pass.args = std::move(args);
  pass.process =
      std::make_unique<RunningProcess>(executable, pass.args, scene_folder, pass.log, pass.output);
  if (one_at_a_time) finish(pass);
  return pass;
}

double PassRunner::finish(RunningPass& pass) const {
  if (!pass.seconds) pass.seconds = wait_for(pass);
  return *pass.seconds;
}

double PassRunner::wait_for(RunningPass& pass) const {
  double seconds = 0.0;
  RenderResult result;
  while (true) {
    // The image is complete once POV-Ray closes it; its shutdown after that is not waited for.
    result = pass.process->wait_for_output();
    seconds += result.seconds;
    if (result.output_written) return seconds;
    std::error_code ec;
    if (result.exit_status == 0 && fs::is_regular_file(pass.output, ec)) return seconds;
    if (pass.attempts >= kStartupAttempts || !povray_startup_timed_out(pass.log, pass.log_start))
      break;
    // Nothing was rendered: a busy machine, not the scene. Wait a little longer each time.
    const int wait_ms = 500 << (pass.attempts - 1);
    ++pass.attempts;
    if (FILE* file = std::fopen(pass.log.c_str(), "a")) {
      std::fprintf(file,
                   "\npovray-ssao: POV-Ray's worker thread did not start in time (a busy "
                   "machine?); run %d of %d in %d ms\n\n",
                   pass.attempts, kStartupAttempts, wait_ms);
      std::fclose(file);
    }
    pass.log_start = fs::file_size(pass.log, ec);
    if (ec) pass.log_start = 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms));
    if (InterruptGuard::interrupted()) throw ssao_tools::Error("interrupted; nothing written");
    pass.process = std::make_unique<RunningProcess>(executable, pass.args, scene_folder, pass.log,
                                                    pass.output);
  }
  const std::string parse_error = povray_parse_error(pass.log);
  if (!parse_error.empty()) {
    // POV-Ray's own diagnosis says it all: the file, the line and what is wrong.
    throw ssao_tools::Error("POV-Ray cannot parse the scene (" + pass.what + "):\n  " +
                            explain_parse_error(parse_error));
  }
  std::string message = "POV-Ray failed on the " + pass.what;
  message += result.exit_status != 0 ? " (exit status " + std::to_string(result.exit_status) + ")"
                                     : " (no image written)";
  if (pass.attempts > 1) message += ", run " + std::to_string(pass.attempts) + " times";
  message += ". Its last messages:\n" + povray_error_lines(pass.log);
  if (!keep) message += "(--keep DIR keeps the wrappers and the full logs)";
  while (!message.empty() && message.back() == '\n') message.pop_back();
  throw ssao_tools::Error(message);
}

std::string PassRunner::explain_parse_error(const std::string& error) const {
  bool after_scene = error.rfind("File '" + scratch->path() + "/", 0) == 0;
  for (const char* include : {"ssao_depth_post.inc", "ssao_ambient_post.inc"}) {
    after_scene =
        after_scene || error.rfind("File '" + include_folder + "/" + include + "'", 0) == 0;
  }
  const size_t line = error.find("' line ");
  const size_t colon = line == std::string::npos ? line : error.find(": ", line);
  if (!after_scene || colon == std::string::npos) return error;
  return "File '" + scene_name + "', after its last line: " + error.substr(colon + 2) +
         "\n  (POV-Ray reads on after the scene: it leaves a block or directive open, a missing } "
         "or #end)";
}

double PassRunner::render(const std::string& what, const std::string& name,
                          const std::string& wrapper, int width, int height,
                          const std::vector<std::string>& extra) const {
  RunningPass running = start(what, name, wrapper, width, height, extra);
  return finish(running);
}

KeepFiles::~KeepFiles() {
  if (target_.empty()) return;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(scratch_.path(), ec)) {
    fs::copy_file(entry.path(), fs::path(target_) / entry.path().filename(),
                  fs::copy_options::overwrite_existing, ec);
    if (ec) {
      report_.warning("--keep: cannot copy " + entry.path().filename().string() + " to " +
                      in_quotes(target_) + ": " + ec.message());
      return;
    }
  }
  report_.progress("kept the wrappers, logs and passes in %s", target_.c_str());
}

}  // namespace povray_ssao
