#pragma once
// The subcommands of the `sph` program: each registers its options and runs.

#include <functional>

#include <CLI/CLI.hpp>

#include <sph/scene/scene_desc.h>

namespace sph::app {

// Exit codes.
inline constexpr int kOk = 0;         ///< success
inline constexpr int kRunFailed = 1;  ///< the run failed (blow-up, I/O error during the run)
inline constexpr int kBadInput = 2;   ///< bad input (scene, flags, paths)
inline constexpr int kInternal = 70;  ///< internal error (a bug)

/// Adds `sph run` to the app; the returned function runs it after parsing.
std::function<int()> add_run_command(CLI::App& app);
/// Adds `sph compare`.
std::function<int()> add_compare_command(CLI::App& app);
/// Adds `sph bench`.
std::function<int()> add_bench_command(CLI::App& app);
/// Adds `sph validate`.
std::function<int()> add_validate_command(CLI::App& app);
/// Adds `sph render`.
std::function<int()> add_render_command(CLI::App& app);
/// Adds `sph surface`.
std::function<int()> add_surface_command(CLI::App& app);
/// Adds `sph view`.
std::function<int()> add_view_command(CLI::App& app);

}  // namespace sph::app
