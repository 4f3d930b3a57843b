#pragma once
// Running the sph binary from a test: arguments passed verbatim (no word splitting), stdout and
// stderr captured, the exit status decoded.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
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

}  // namespace sph::test
