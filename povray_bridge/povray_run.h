// SPDX-License-Identifier: MIT
// Running POV-Ray: the executable, one render with its output captured in a log file, the error
// lines of a failed render, the image size POV-Ray would use, a scratch folder, Ctrl-C.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "animation.h"
#include "tools/error.h"
#include "tools/interrupt.h"

namespace povray_ssao {

// The full path of `name` (searched in PATH unless it contains a '/'). Throws ssao_tools::Error
// if there is no such executable.
std::string find_executable(const std::string& name);

struct RenderResult {
  int exit_status = 0;          // POV-Ray's exit code (128 + signal if it was killed)
  double seconds = 0.0;         // wall-clock time
  bool output_written = false;  // wait_for_output(): the output file was closed after writing
                                // while the process was still shutting down
};

// `executable args...` running in `working_directory` with stdin from /dev/null and stdout and
// stderr appended to `log_path`, started by the constructor (which throws ssao_tools::Error if it
// cannot start). wait() returns its result; it throws ssao_tools::Error when the user interrupted
// it (SIGINT/SIGTERM, forwarded to POV-Ray) or it could not be executed. A process that is not
// waited for is terminated (SIGTERM) and reaped by the destructor, so a failure elsewhere
// leaves no render behind.
//
// With `output` given, wait_for_output() also returns as soon as the process has closed that
// file after writing it (inotify): POV-Ray 3.7 writes its image last and then spends about 0.3 s
// shutting down (message polling), which need not be waited for. Such a process is killed
// (SIGKILL) and reaped by the destructor unless it has exited by then.
class RunningProcess {
 public:
  RunningProcess(const std::string& executable, const std::vector<std::string>& args,
                 const std::string& working_directory, const std::string& log_path,
                 const std::string& output = "");
  ~RunningProcess();
  RunningProcess(const RunningProcess&) = delete;
  RunningProcess& operator=(const RunningProcess&) = delete;
  RenderResult wait();
  RenderResult wait_for_output();

 private:
  RenderResult reaped(int status);
  std::string executable_, working_directory_, log_path_, output_name_;
  pid_t child_ = -1;
  int inotify_ = -1;
  bool output_written_ = false;
  std::chrono::steady_clock::time_point start_;
};

// Starts the process and waits for it.
RenderResult run_process(const std::string& executable, const std::vector<std::string>& args,
                         const std::string& working_directory, const std::string& log_path);

// The lines of a POV-Ray log that explain a failure (from the first error message on, at most
// `max_lines`), or its last lines when it has no recognisable error message.
std::string povray_error_lines(const std::string& log_path, size_t max_lines = 15);

// POV-Ray's parse error in a log: "File 'scene.pov' line 5: Parse Error: No matching } in
// 'sphere', box found instead" (its wrapped lines joined; "Possible Parse Error" warnings
// skipped), or "" when the log has none.
std::string povray_parse_error(const std::string& log_path);

// Whether a log, from byte `from` on, shows that POV-Ray gave up waiting for its worker thread to
// start ("Timed out waiting for worker thread startup"): it rendered nothing, and a second run
// may well succeed.
bool povray_startup_timed_out(const std::string& log_path, uintmax_t from = 0);

// Width and height set by an INI file (Width=, Height=, +W, +H before the first [section]);
// 0 for a value it does not set. Throws ssao_tools::Error if the file cannot be read.
void ini_size(const std::string& path, int& width, int& height);

// The library paths an INI file adds (Library_Path=..., +L...), appended to `paths`.
void ini_library_paths(const std::string& path, std::vector<std::string>& paths);

// The Declare=NAME=VALUE settings (appended to `declares` as NAME=VALUE), the clock and the
// animation options (Clock=, +K, +KFI, ...: animation.h) of an INI file or of a list of
// command-line options.
void ini_declares(const std::string& path, std::vector<std::string>& declares, ClockOptions& clock);
void option_declares(const std::vector<std::string>& options, std::vector<std::string>& declares,
                     ClockOptions& clock);

// The INI file POV-Ray reads at start-up: $POVINI, ./povray.ini in `working_directory`,
// ~/.povray/3.7/povray.ini or /etc/povray/3.7/povray.ini, the first that exists; "" if none.
std::string system_ini(const std::string& working_directory);

// The size POV-Ray uses when the command line sets none: the first INI file POV-Ray reads at
// start-up ($POVINI, ./povray.ini in `working_directory`, ~/.povray/3.7/povray.ini,
// /etc/povray/3.7/povray.ini), else its built-in 160 x 120. Fills only values still 0.
void default_size(const std::string& working_directory, int& width, int& height);

// A private folder under $TMPDIR (or /tmp), removed with its contents on destruction.
class ScratchFolder {
 public:
  ScratchFolder();
  ~ScratchFolder();
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// Ctrl-C: the tools' one guard (the scratch folder is removed, no partial output is left).
using ssao_tools::InterruptGuard;

}  // namespace povray_ssao
