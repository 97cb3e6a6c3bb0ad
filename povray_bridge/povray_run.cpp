// SPDX-License-Identifier: MIT
#include "povray_run.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace povray_ssao {

namespace fs = std::filesystem;

namespace {

bool is_executable_file(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec) && ::access(path.c_str(), X_OK) == 0;
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string trim(const std::string& text) {
  size_t begin = 0, end = text.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(text[begin]))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
  return text.substr(begin, end - begin);
}

int parse_positive(const std::string& text) {
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (end == text.c_str() || value <= 0 || value > 1000000) return 0;
  return static_cast<int>(value);
}

}  // namespace

std::string find_executable(const std::string& name) {
  if (name.find('/') != std::string::npos) {
    if (is_executable_file(name)) return name;
    throw ssao_tools::Error("cannot run POV-Ray: '" + name + "' is not an executable file");
  }
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (folder.empty()) folder = ".";
    const std::string candidate = folder + "/" + name;
    if (is_executable_file(candidate)) return candidate;
  }
  throw ssao_tools::Error("cannot run POV-Ray: no '" + name +
                          "' in PATH (install POV-Ray 3.7, e.g. apt-get install povray, or give "
                          "--povray PATH)");
}

RunningProcess::RunningProcess(const std::string& executable, const std::vector<std::string>& args,
                               const std::string& working_directory, const std::string& log_path,
                               const std::string& output)
    : executable_(executable), working_directory_(working_directory), log_path_(log_path) {
  if (!output.empty()) {
    // Watched before the process starts, so that no close can be missed.
    inotify_ = ::inotify_init1(IN_CLOEXEC | IN_NONBLOCK);
    const fs::path folder = fs::path(output).parent_path();
    if (inotify_ >= 0 &&
        ::inotify_add_watch(inotify_, folder.empty() ? "." : folder.c_str(), IN_CLOSE_WRITE) < 0) {
      ::close(inotify_);
      inotify_ = -1;
    }
    output_name_ = fs::path(output).filename().string();
  }
  const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log < 0) {
    throw ssao_tools::Error("cannot create the log file '" + log_path +
                            "': " + std::strerror(errno));
  }
  std::vector<std::string> argv_strings;
  argv_strings.push_back(executable);
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& arg : argv_strings) argv.push_back(arg.data());
  argv.push_back(nullptr);

  start_ = std::chrono::steady_clock::now();
  const pid_t parent = ::getpid();
  child_ = ::fork();
  if (child_ < 0) {
    ::close(log);
    throw ssao_tools::Error(std::string("cannot start POV-Ray: fork failed: ") +
                            std::strerror(errno));
  }
  if (child_ == 0) {
    // The child: only async-signal-safe calls until exec.
    // A povray-ssao killed outright (SIGKILL from a test's or a farm's time limit) cannot stop
    // its renders; the kernel does it for it, or they would render on for nothing, for hours at
    // a large size. If it died before this line, the child is already an orphan: stop. (The
    // signal follows the thread that forked: renders are started from the main thread only.)
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(125);
    const int null_in = ::open("/dev/null", O_RDONLY);
    if (null_in >= 0) ::dup2(null_in, 0);
    ::dup2(log, 1);
    ::dup2(log, 2);
    if (::chdir(working_directory.c_str()) != 0) {
      const char message[] = "povray-ssao: cannot enter the scene's folder\n";
      (void)!::write(2, message, sizeof message - 1);
      ::_exit(126);
    }
    ::execv(executable.c_str(), argv.data());
    const char message[] = "povray-ssao: cannot execute POV-Ray\n";
    (void)!::write(2, message, sizeof message - 1);
    ::_exit(127);
  }
  ::close(log);
}

RunningProcess::~RunningProcess() {
  if (inotify_ >= 0) ::close(inotify_);
  if (child_ <= 0) return;
  // Not waited for: an error elsewhere ends the run, so this render is not needed; or its image
  // is written and it is only shutting down.
  ::kill(child_, output_written_ ? SIGKILL : SIGTERM);
  int status = 0;
  while (::waitpid(child_, &status, 0) < 0 && errno == EINTR) {
  }
}

RenderResult RunningProcess::wait_for_output() {
  if (inotify_ < 0) return wait();
  if (child_ <= 0) throw ssao_tools::Error("internal error: waited twice for a POV-Ray run");
  alignas(inotify_event) char buffer[4096];
  while (true) {
    int status = 0;
    const pid_t done = ::waitpid(child_, &status, WNOHANG);
    if (done == child_) return reaped(status);
    if (done < 0 && errno != EINTR) {
      throw ssao_tools::Error(std::string("waiting for POV-Ray failed: ") + std::strerror(errno));
    }
    if (InterruptGuard::interrupted()) return wait();  // forwards the interruption and throws
    pollfd events{inotify_, POLLIN, 0};
    if (::poll(&events, 1, 20) <= 0) continue;  // 20 ms: also the exit check's period
    const ssize_t length = ::read(inotify_, buffer, sizeof buffer);
    for (ssize_t offset = 0; offset < length;) {
      const auto* event = reinterpret_cast<const inotify_event*>(buffer + offset);
      if (event->len > 0 && output_name_ == event->name) output_written_ = true;
      offset += static_cast<ssize_t>(sizeof(inotify_event) + event->len);
    }
    if (output_written_) {
      RenderResult result;
      result.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
      result.output_written = true;
      return result;
    }
  }
}

RenderResult RunningProcess::wait() {
  if (child_ <= 0) throw ssao_tools::Error("internal error: waited twice for a POV-Ray run");
  int status = 0;
  bool forwarded = false;
  while (true) {
    const pid_t done = ::waitpid(child_, &status, 0);
    if (done == child_) break;
    if (done < 0 && errno != EINTR) {
      throw ssao_tools::Error(std::string("waiting for POV-Ray failed: ") + std::strerror(errno));
    }
    if (InterruptGuard::interrupted() && !forwarded) {
      ::kill(child_, SIGTERM);
      forwarded = true;
    }
  }
  return reaped(status);
}

RenderResult RunningProcess::reaped(int status) {
  child_ = -1;
  RenderResult result;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (WIFEXITED(status)) {
    result.exit_status = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.exit_status = 128 + WTERMSIG(status);
  }
  if (InterruptGuard::interrupted()) throw ssao_tools::Error("interrupted; nothing written");
  if (result.exit_status == 127 || result.exit_status == 126) {
    std::ifstream file(log_path_);
    std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (text.find("povray-ssao: cannot execute POV-Ray") != std::string::npos) {
      throw ssao_tools::Error("cannot execute '" + executable_ + "'");
    }
    if (text.find("povray-ssao: cannot enter the scene's folder") != std::string::npos) {
      throw ssao_tools::Error("cannot enter the scene's folder '" + working_directory_ + "'");
    }
  }
  return result;
}

RenderResult run_process(const std::string& executable, const std::vector<std::string>& args,
                         const std::string& working_directory, const std::string& log_path) {
  RunningProcess process(executable, args, working_directory, log_path);
  return process.wait();
}

std::string povray_error_lines(const std::string& log_path, size_t max_lines) {
  std::ifstream file(log_path);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(file, line)) {
    if (!trim(line).empty()) lines.push_back(line);
  }
  // POV-Ray's messages: "File 'x.pov' line 4: Parse Error: ...", "Possible Parse Error: ...",
  // "Fatal error in parser: ...", "Render failed". The banner lists "Error Stream to console".
  size_t first = lines.size();
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (l.find("Stream to console") != std::string::npos) continue;
    if (l.find("Error") != std::string::npos || l.find("Fatal error") != std::string::npos ||
        l.find("povray-ssao:") == 0 || l.find("Render failed") != std::string::npos) {
      if (l.find("povray-ssao: ") == 0 && l.find("cannot") == std::string::npos) continue;
      first = i;
      break;
    }
  }
  if (first == lines.size()) first = lines.size() > max_lines ? lines.size() - max_lines : 0;
  std::string out;
  for (size_t i = first; i < lines.size() && i < first + max_lines; ++i) {
    out += "  " + lines[i] + "\n";
  }
  return out;
}

bool povray_startup_timed_out(const std::string& log_path, uintmax_t from) {
  std::ifstream file(log_path, std::ios::binary);
  file.seekg(static_cast<std::streamoff>(from));
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  return text.find("Timed out waiting for worker thread startup") != std::string::npos;
}

std::string povray_parse_error(const std::string& log_path) {
  // POV-Ray wraps its messages at 80 columns (anywhere between words, "Parse Error:" included);
  // the continuation lines start with a space.
  std::ifstream file(log_path);
  std::vector<std::string> messages;
  std::string line;
  while (std::getline(file, line)) {
    if (!messages.empty() && !line.empty() && line[0] == ' ') {
      messages.back() += " " + trim(line);
    } else {
      messages.push_back(trim(line));
    }
  }
  for (const std::string& message : messages) {
    if (message.find("Parse Error:") != std::string::npos &&
        message.find("Possible Parse Error:") == std::string::npos) {
      return message;
    }
  }
  return "";
}

namespace {

// The lines POV-Ray reads from an INI file: comments (';') stripped, trimmed, empty lines
// dropped, up to the first named section (POV-Ray reads only the unnamed one by default).
std::vector<std::string> ini_lines(const std::string& path, bool required) {
  std::ifstream file(path);
  if (!file && required) throw ssao_tools::Error("cannot read the INI file '" + path + "'");
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(file, line)) {
    const size_t comment = line.find(';');
    if (comment != std::string::npos) line.resize(comment);
    line = trim(line);
    if (line.empty()) continue;
    if (line[0] == '[') break;
    lines.push_back(line);
  }
  return lines;
}

}  // namespace

void ini_size(const std::string& path, int& width, int& height) {
  for (const std::string& line : ini_lines(path, true)) {
    if ((line[0] == '+' || line[0] == '-') && line.size() > 2) {
      // Switches, possibly several on one line.
      std::stringstream words(line);
      std::string word;
      while (words >> word) {
        if (word.size() < 3 || (word[0] != '+' && word[0] != '-')) continue;
        const char key = static_cast<char>(std::toupper(static_cast<unsigned char>(word[1])));
        const int value = parse_positive(word.substr(2));
        if (key == 'W' && value) width = value;
        if (key == 'H' && value) height = value;
      }
      continue;
    }
    const size_t equals = line.find('=');
    if (equals == std::string::npos) continue;
    const std::string key = lower(trim(line.substr(0, equals)));
    const int value = parse_positive(trim(line.substr(equals + 1)));
    if (key == "width" && value) width = value;
    if (key == "height" && value) height = value;
  }
}

void ini_library_paths(const std::string& path, std::vector<std::string>& paths) {
  for (const std::string& line : ini_lines(path, false)) {
    std::string value;
    if ((line[0] == '+' || line[0] == '-') && line.size() > 2 &&
        std::toupper(static_cast<unsigned char>(line[1])) == 'L') {
      value = line.substr(2);
    } else {
      const size_t equals = line.find('=');
      if (equals == std::string::npos) continue;
      if (lower(trim(line.substr(0, equals))) != "library_path") continue;
      value = trim(line.substr(equals + 1));
    }
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') {
      value = value.substr(1, value.size() - 2);
    }
    if (!value.empty()) paths.push_back(value);
  }
}

namespace {

// One INI line or command-line option: Declare=NAME=VALUE, or a clock or animation option.
void declare_option(const std::string& text, std::vector<std::string>& declares,
                    ClockOptions& clock) {
  if (read_clock_option(text, clock)) return;
  const std::string option = trim(text);
  const size_t equals = option.find('=');
  if (equals == std::string::npos) return;
  const std::string key = lower(trim(option.substr(0, equals)));
  if (key == "declare") declares.push_back(trim(option.substr(equals + 1)));
}

}  // namespace

void ini_declares(const std::string& path, std::vector<std::string>& declares,
                  ClockOptions& clock) {
  for (const std::string& line : ini_lines(path, false)) {
    if (line[0] == '+' || line[0] == '-') {
      std::stringstream words(line);
      std::string word;
      while (words >> word) declare_option(word, declares, clock);
      continue;
    }
    declare_option(line, declares, clock);
  }
}

void option_declares(const std::vector<std::string>& options, std::vector<std::string>& declares,
                     ClockOptions& clock) {
  for (const std::string& option : options) declare_option(option, declares, clock);
}

std::string system_ini(const std::string& working_directory) {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("POVINI")) candidates.push_back(env);
  candidates.push_back(working_directory + "/povray.ini");
  if (const char* home = std::getenv("HOME")) {
    candidates.push_back(std::string(home) + "/.povray/3.7/povray.ini");
  }
  candidates.push_back("/etc/povray/3.7/povray.ini");
  for (const std::string& candidate : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec)) return candidate;  // POV-Ray reads only this one
  }
  return "";
}

void default_size(const std::string& working_directory, int& width, int& height) {
  const std::string ini = system_ini(working_directory);
  if (!ini.empty()) {
    int w = 0, h = 0;
    try {
      ini_size(ini, w, h);
    } catch (const ssao_tools::Error&) {
    }
    if (width == 0) width = w;
    if (height == 0) height = h;
  }
  if (width == 0) width = 160;
  if (height == 0) height = 120;
}

ScratchFolder::ScratchFolder() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/povray-ssao.XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (!::mkdtemp(buffer.data())) {
    throw ssao_tools::Error("cannot create a scratch folder '" + pattern +
                            "': " + std::strerror(errno));
  }
  path_ = buffer.data();
}

ScratchFolder::~ScratchFolder() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

}  // namespace povray_ssao
