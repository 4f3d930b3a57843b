// The `sph` command-line program: thin layer over the library (parse, call, report).

#include <cstdio>
#include <exception>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/version.h>

#include "commands.h"

int main(int argc, char** argv) {
  using namespace sph::app;
  CLI::App app{"sph: Smoothed Particle Hydrodynamics fluids in 2D and 3D with adaptive neighbor pairing.\n"
               "Run a scene:   sph run scenes/paper/dam_break_2d.json -o out/dam_break_2d\n"
               "Then open out/dam_break_2d/frames.pvd in ParaView.",
               "sph"};
  app.set_version_flag("--version", std::string("sph ") + sph::kVersion);
  app.require_subcommand(1);
  std::function<int()> run = add_run_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "sph: error: {}\nRun 'sph --help' or 'sph run --help' for usage.\n", e.what());
    return kBadInput;
  }

  try {
    return run();
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
