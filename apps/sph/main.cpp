// The `sph` command-line program: thin layer over the library (parse, call, report).

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>

#include <sph/analysis/validation.h>
#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/spelling.h>
#include <sph/core/version.h>
#include <sph/neighbors/neighbor_mode.h>

#include "commands.h"

namespace {

/// The options `app` takes ("--name", "-n"): its own, and its subcommands' when `subcommands`.
std::vector<std::string> option_names(const CLI::App& app, bool subcommands) {
  std::vector<const CLI::App*> apps{&app};
  if (subcommands)
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) apps.push_back(sub);
  std::vector<std::string> names;
  for (const CLI::App* x : apps)
    for (const CLI::Option* o : x->get_options()) {
      for (const auto& n : o->get_lnames()) names.push_back("--" + n);
      for (const auto& n : o->get_snames()) names.push_back("-" + n);
    }
  return names;
}

/// The first argument that looks like an option and is none of sph's ("" if none), with the
/// option of the command given (`command`, or the top level's) it was probably meant to be.
std::string first_unknown_option(CLI::App& app, const CLI::App* command, int argc, char** argv) {
  const std::vector<std::string> known = option_names(app, true);
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--") break;
    if (a.size() < 2 || a[0] != '-') continue;
    if (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.') continue;  // a negative number
    if (const auto eq = a.find('='); eq != std::string::npos) a = a.substr(0, eq);
    if (std::find(known.begin(), known.end(), a) != known.end()) continue;
    std::vector<std::string> offered = option_names(command ? *command : app, false);
    if (command) offered.push_back("--help");
    return a + sph::did_you_mean(a, offered, "");
  }
  return {};
}

/// `description` as the rest of a sentence: its first letter in lower case.
std::string lower_first(std::string description) {
  if (!description.empty())
    description[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(description[0])));
  return description;
}

/// CLI11's message for a missing argument or value, said as sph's messages say things (what is
/// missing, and what is expected), or "" for the other errors. CLI11 says "scene is required"
/// and "--output: 1 required TEXT missing".
std::string missing_value_message(const CLI::ParseError& e, const CLI::App& command) {
  const std::string message = e.what();
  if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr) {
    const auto end = message.find(" is required");
    if (end == std::string::npos) return {};
    const CLI::Option* o = command.get_option_no_throw(message.substr(0, end));
    if (o == nullptr || !o->get_positional()) return {};
    std::string name = o->get_name();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::toupper(c); });
    return fmt::format("sph {} needs {}: {}", command.get_name(), name, lower_first(o->get_description()));
  }
  if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) != nullptr) {
    const auto colon = message.find(": ");
    if (colon == std::string::npos || message.find(" missing", colon) == std::string::npos) return {};
    const std::string flag = message.substr(0, colon);
    const CLI::Option* o = command.get_option_no_throw(flag);
    if (o == nullptr) return {};
    return fmt::format("{} needs a value: {}", flag, lower_first(o->get_description()));
  }
  return {};
}

}  // namespace

/// OpenMP threads that spin long while they wait (libgomp's default) make every step 10 to 80
/// times slower as soon as another program competes for the cores; threads that sleep at once
/// (OMP_WAIT_POLICY=passive) make small scenes 2.5 times slower on idle cores. A short spin, of
/// about kSpinMicroseconds (GOMP_SPINCOUNT calibrated on this CPU), is nearly as fast as spinning
/// on idle cores and bounded under contention (docs/performance.md, Threads). libgomp reads these
/// once, when it loads, before main: the only way to choose a default is to restart the program
/// with it set. A setting the user made (either variable) is kept.
static void default_to_short_spin(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  const std::string count = std::to_string(sph::spin_count_lasting(sph::kSpinMicroseconds));
  if (setenv("GOMP_SPINCOUNT", count.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);  // returns only if it failed: then run with libgomp's default
}

int main(int argc, char** argv) {
  default_to_short_spin(argv);
  using namespace sph::app;
  // The synopsis names the modes and cases from their tables, so that it lists every one.
  const std::string synopsis = fmt::format(
      "sph: Smoothed Particle Hydrodynamics fluids in 2D and 3D with adaptive neighbor pairing.\n\n"
      "  sph run SCENE.json [-o DIR] [--neighbors MODE] [--steps N] [--threads N]\n"
      "                     [--set KEY=VALUE]... [--checkpoint-every N] [--strict]   run a scene (sph run --help);\n"
      "                     health warnings end it \"completed with warnings\" (--strict: failed, exit 1)\n"
      "  sph run --resume DIR [--steps N]   continue an interrupted run from its checkpoint (or a\n"
      "                     finished one further: --steps above the steps it did)\n"
      "  sph compare SCENE.json [-o DIR] [--modes MODE,...] [--steps N]\n"
      "                     compare the neighbor modes (all but brute_force unless --modes says):\n"
      "                     speed, accuracy, missed pairs, images\n"
      "  sph bench [--suite neighbors,steps,tank|all] [--size small|medium|large|full] [--threads 1,2]\n"
      "                     [-o DIR]   benchmark suites: tables, DIR/bench.json and CSVs\n"
      "  sph validate [--cases CASE,...|all] [--quick] [-o DIR]\n"
      "                     validate against experiment and physics: report, plots, CSVs (exit 1 on a miss)\n"
      "  sph render DIR [--color-by speed|kinetic_energy|density|pressure|initial_position|none] [--mp4]\n"
      "                     PNG images (and an MP4) of a run's frames; a comparison's runs side by side\n"
      "  sph surface DIR [--frames all] [--resolution 2] [--smoothing 2] [--format ply,obj,vdb]\n"
      "                     free-surface meshes (PLY, OBJ) and OpenVDB level sets of a run's frames\n"
      "  sph view DIR [-o FILE.html] [--max-frames N] [--color-by LIST]\n"
      "                     one HTML page that plays the run in 3D in a browser, offline\n\n"
      "  MODE: {} (docs/neighbor-modes.md)\n"
      "  CASE: {} (docs/validation.md)\n\n"
      "Example: sph run scenes/paper/dam_break_2d.json -o out/dam_break_2d\n"
      "         sph render out/dam_break_2d --mp4   (pictures and a movie in out/dam_break_2d/render/)\n"
      "         sph view out/dam_break_2d           (out/dam_break_2d/view.html: open it in a browser)\n"
      "         or open out/dam_break_2d/frames.pvd in ParaView.",
      sph::join_neighbor_mode_names(sph::NeighborModeSet::All, ", ", ", "), fmt::join(sph::kValidationCases, ", "));
  CLI::App app{synopsis, "sph"};
  app.set_version_flag("--version", std::string("sph ") + sph::kVersion);
  app.require_subcommand(1);
  std::function<int()> run_cmd = add_run_command(app);
  std::function<int()> compare_cmd = add_compare_command(app);
  std::function<int()> bench_cmd = add_bench_command(app);
  std::function<int()> validate_cmd = add_validate_command(app);
  std::function<int()> render_cmd = add_render_command(app);
  std::function<int()> view_cmd = add_view_command(app);
  std::function<int()> surface_cmd = add_surface_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // CLI11 reports a missing subcommand or argument before an unknown option: name the
    // option the user mistyped first, since that is usually the real mistake.
    std::string message = e.what();
    std::vector<std::string> commands;
    for (const CLI::App* c : app.get_subcommands([](CLI::App*) { return true; })) commands.push_back(c->get_name());
    // The subcommand the user typed, if any: its options are those a mistyped one is matched
    // against, and its help the one pointed at.
    const CLI::App* command = nullptr;
    for (int i = 1; i < argc && command == nullptr; ++i)
      if (std::find(commands.begin(), commands.end(), std::string(argv[i])) != commands.end())
        command = app.get_subcommand(argv[i]);
    if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr && command != nullptr) {
      // (CLI11: "The following argument(s) was (were) not expected: X Y")
      const auto colon = message.find(": ");
      const std::string extra = colon == std::string::npos ? std::string() : message.substr(colon + 2);
      message = fmt::format("unexpected argument{} {}; sph {} takes only the arguments its help lists",
                            extra.find(' ') == std::string::npos ? "" : "s", extra, command->get_name());
    }
    if (command != nullptr)
      if (std::string missing = missing_value_message(e, *command); !missing.empty()) message = std::move(missing);
    const std::string unknown = first_unknown_option(app, command, argc, argv);
    if (!unknown.empty()) message = "unknown option " + unknown;
    // A mistyped command (sph rnu scene.json): CLI11 says only that a subcommand is required.
    if (argc > 1 && argv[1][0] != '-' &&
        std::find(commands.begin(), commands.end(), std::string(argv[1])) == commands.end())
      message = fmt::format("unknown command \"{}\"{}; expected one of: {}", argv[1],
                            sph::did_you_mean(argv[1], commands), fmt::join(commands, ", "));
    else if (command == nullptr && unknown.empty() && dynamic_cast<const CLI::RequiredError*>(&e) != nullptr)
      message = fmt::format("expected a command: {}", fmt::join(commands, ", "));
    if (command == nullptr)
      fmt::print(stderr, "sph: error: {}\nRun 'sph --help' for usage.\n", message);
    else
      fmt::print(stderr, "sph: error: {}\nRun 'sph {} --help' for usage.\n", message, command->get_name());
    return kBadInput;
  }

  try {
    if (app.got_subcommand("bench")) return bench_cmd();
    if (app.got_subcommand("validate")) return validate_cmd();
    if (app.got_subcommand("render")) return render_cmd();
    if (app.got_subcommand("view")) return view_cmd();
    if (app.got_subcommand("surface")) return surface_cmd();
    return app.got_subcommand("compare") ? compare_cmd() : run_cmd();
  } catch (const sph::Error& e) {
    fmt::print(stderr, "sph: error: {}\n", e.what());
    return kBadInput;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "sph: error: out of memory; the scene holds more particles than this machine can store\n");
    return kBadInput;
  } catch (const std::exception& e) {
    fmt::print(stderr, "sph: {}\n", e.what());
    return kInternal;
  }
}
