#pragma once
// Running the sph binary from a test: arguments passed verbatim (no word splitting), stdout and
// stderr captured, the exit status decoded.

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "support/temp_dir.h"

namespace sph::test {

inline std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

struct CommandResult {
  int code = -1;    ///< exit status, or 128 + signal
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// The lines of a program's stderr that are an error message ("sph: error: ...").
inline std::vector<std::string> error_lines(const std::string& err) {
  std::vector<std::string> out;
  std::istringstream in(err);
  for (std::string l; std::getline(in, l);)
    if (l.rfind("sph: error:", 0) == 0) out.push_back(l);
  return out;
}

/// Runs `env_prefix SPH_BINARY args...` in `cwd` (env_prefix, e.g. "env -u VAR", may be empty);
/// stderr goes through `err_file`.
inline CommandResult run_sph(const std::vector<std::string>& args, const std::filesystem::path& cwd,
                             const std::filesystem::path& err_file, const std::string& env_prefix = "") {
  std::string cmd = "cd " + shell_quote(cwd.string()) + " && " + env_prefix + " " + shell_quote(SPH_BINARY);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  cmd += " 2>" + shell_quote(err_file.string());
  CommandResult r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = ::pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
  r.err = slurp(err_file);
  return r;
}

/// A running `sph` process (for tests that signal or kill it). Killed and reaped at scope exit
/// if still running.
class SphProcess {
 public:
  /// Starts SPH_BINARY args... in `cwd`, stdout and stderr to `log`.
  SphProcess(const std::vector<std::string>& args, const std::filesystem::path& cwd, const std::filesystem::path& log) {
    // sh changes directory, then becomes sph (exec): the pid is sph's.
    std::string script = "cd " + shell_quote(cwd.string()) + " && exec " + shell_quote(SPH_BINARY);
    for (const auto& a : args) script += " " + shell_quote(a);
    std::string sh = "/bin/sh", c = "-c";
    char* argv[] = {sh.data(), c.data(), script.data(), nullptr};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    if (::posix_spawn(&pid_, "/bin/sh", &fa, nullptr, argv, environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
  }
  SphProcess(const SphProcess&) = delete;
  SphProcess& operator=(const SphProcess&) = delete;
  ~SphProcess() {
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, SIGKILL);
      wait();
    }
  }
  bool started() const { return pid_ > 0; }
  void signal(int sig) const { ::kill(pid_, sig); }
  /// Waits for the exit; returns the exit status, or 128 + the signal that killed it.
  int wait() {
    if (reaped_) return code_;
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    reaped_ = true;
    code_ = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
    return code_;
  }

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int code_ = -1;
};

}  // namespace sph::test
