// `sph validate [--cases ...] [--quick] [-o DIR]`: runs the validation cases (dam break against
// Martin & Moyce 1952, resolution study, hydrostatic tanks, conservation) and writes a report.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <sph/analysis/validation.h>
#include <sph/core/data_dir.h>
#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/timer.h>

#include "cli_checks.h"
#include "commands.h"

namespace sph::app {

namespace {

namespace fs = std::filesystem;

struct ValidateCliOptions {
  std::string cases = "all";
  std::string output = "out/validation";
  std::string scenes;  // empty: the validation scenes installed with sph (scene_dir)
  int threads = 0;
  bool quick = false;
  bool no_progress = false;
};

std::vector<std::string> parse_cases(const std::string& list) {
  std::vector<std::string> cases;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) {
    if (item == "all") {
      for (const char* c : kValidationCases)
        if (std::find(cases.begin(), cases.end(), c) == cases.end()) cases.emplace_back(c);
      continue;
    }
    check_validation_case(item);
    if (std::find(cases.begin(), cases.end(), item) != cases.end())
      throw Error("case \"" + item + "\" is listed twice", "--cases");
    cases.push_back(item);
  }
  if (cases.empty()) throw Error("no case given; expected e.g. martin_moyce,hydrostatic or all", "--cases");
  return cases;
}

int validate(const ValidateCliOptions& opt) {
  ValidationOptions vo;
  vo.cases = parse_cases(opt.cases);
  vo.quick = opt.quick;
  vo.scene_dir = opt.scenes.empty() ? scene_dir("validation") : fs::path(opt.scenes);
  if (!fs::is_directory(vo.scene_dir))
    throw Error("not a directory; expected the directory of the validation scenes (scenes/validation)", opt.scenes);
  if (opt.threads > 0) set_num_threads(opt.threads);
  check_output_path(opt.output, "-o/--output");
  const fs::path dir(opt.output);
  check_validation_scenes(vo);  // a bad scene is refused before the output directory is touched
  prepare_validation_directory(dir);

  std::string list;
  for (const auto& c : vo.cases) list += (list.empty() ? "" : ",") + c;
  fmt::print(stderr, "sph: validate {}{} ({} thread{}) -> {}\n", list, opt.quick ? " (quick)" : "", num_threads(),
             num_threads() == 1 ? "" : "s", dir.string());
  fmt::print(stderr, "sph: scenes from {}\n", vo.scene_dir.string());
  const ValidationProgress progress = [&](const std::string& line) {
    if (!opt.no_progress) fmt::print(stderr, "sph: {}\n", line);
  };
  const ValidationResult result = run_validation(vo, progress);
  write_validation(dir, result);

  // The results go to stdout (as bench's tables do), what happened around them to stderr.
  fmt::print(stderr, "sph: validated in {:.1f} s:\n", result.seconds);
  for (const ValidationCheck& c : result.checks)
    fmt::print(stdout, "  {}  {}: {} = {:.4g} (target {}{})\n", c.pass ? "PASS" : "MISS", c.case_name, c.what, c.value,
               c.target, c.regression ? ", regression bound" : "");
  std::fflush(stdout);
  fmt::print(stderr, "  report: {}\n", (dir / "report.md").string());
  if (!result.passed()) {
    std::size_t missed = 0;
    for (const auto& c : result.checks) missed += !c.pass;
    fmt::print(stderr, "sph: {} of {} checks missed their target (see the report)\n", missed, result.checks.size());
    return kRunFailed;
  }
  return kOk;
}

}  // namespace

std::function<int()> add_validate_command(CLI::App& app) {
  auto opt = std::make_shared<ValidateCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "validate",
      "Validate against experiment and physics: dam break vs Martin & Moyce (1952), resolution, hydrostatics, "
      "conservation; exit 1 if a check misses its target");
  cmd->add_option(
         "--cases", opt->cases,
         "Comma-separated cases: martin_moyce, resolution, hydrostatic, boundaries, dfsph, conservation, or all")
      ->default_str("all");
  cmd->add_flag("--quick", opt->quick,
                "Coarse, short versions (under a minute) with regression bounds instead of the targets (CI)");
  cmd->add_option("-o,--output", opt->output, "Output directory (report.md, CSVs, plots)")
      ->default_str("out/validation");
  cmd->add_option("--scenes", opt->scenes, "Directory of the validation scenes")
      ->check(not_empty("the directory of the validation scenes"))
      ->default_str("the validation scenes of sph's data: <prefix>/share/sph/scenes/validation");
  cmd->add_option("--threads", opt->threads, "Worker threads (default: all cores)")->check(in_range(1, 4096));
  cmd->add_flag("--no-progress", opt->no_progress, "No progress lines");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return kBadInput;
    return validate(*opt);
  };
}

}  // namespace sph::app
