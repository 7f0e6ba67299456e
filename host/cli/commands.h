#pragma once
// Each subcommand registers its options on the app and returns what to run once parsing is done.
#include <CLI/CLI.hpp>

#include <functional>

namespace pneumo::cli {

using Run = std::function<int()>;   // returns the exit code

Run add_info(CLI::App& app);
Run add_convert(CLI::App& app);
Run add_devices(CLI::App& app);
Run add_phantom(CLI::App& app);
Run add_scene(CLI::App& app);
Run add_roles(CLI::App& app);
Run add_validate(CLI::App& app);
Run add_simulate(CLI::App& app);
Run add_render(CLI::App& app);
Run add_run(CLI::App& app);
Run add_warp(CLI::App& app);
Run add_bench(CLI::App& app);
Run add_serve(CLI::App& app);
Run add_ports(CLI::App& app);

}  // namespace pneumo::cli
