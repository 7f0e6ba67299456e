// pneumo: one executable whose subcommands map one to one onto library calls.
// Exit codes: 0 success, 1 failure, 2 bad input (a file, a scene, an argument).
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/unknown_subcommand.h"
#include "core/allocator_policy.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "core/thread_count.h"

namespace {
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;
}  // namespace

int main(int argc, char** argv) {
  using namespace pneumo;
  keep_freed_memory_for_reuse();   // before the first large block
  CLI::App app{"pneumo: virtual pneumoperitoneum, from a CT to the laparoscope's view"};
  app.set_version_flag("--version", std::string("pneumo ") + PNEUMO_VERSION);
  app.require_subcommand(1);
  bool verbose = false, quiet = false;
  app.add_flag("-v,--verbose", verbose, "Show debug messages (device, build options, timings)");
  app.add_flag("-q,--quiet", quiet, "Show errors only (no progress)");
  int threads = 0;
  CLI::Option* threads_option = app.add_option(
      "--threads", threads, "CPU threads for pneumo's loops and PoCL's CPU device, 1 to 1024 (default: at each stage, the cores other processes leave free)");

  std::vector<std::pair<CLI::App*, cli::Run>> commands;
  auto add = [&](cli::Run (*make)(CLI::App&)) {
    const std::size_t before = app.get_subcommands({}).size();
    cli::Run run = make(app);
    CLI::App* sub = app.get_subcommands({})[before];
    // -v, -q and --threads anywhere on the line: after the subcommand too, and after its own ones
    // (`validate lattice -q`).
    std::function<void(CLI::App*)> fall_through = [&](CLI::App* a) {
      a->fallthrough();
      for (CLI::App* nested : a->get_subcommands({})) fall_through(nested);
    };
    fall_through(sub);
    commands.emplace_back(sub, std::move(run));
  };
  add(cli::add_info);
  add(cli::add_convert);
  add(cli::add_devices);
  add(cli::add_phantom);
  add(cli::add_scene);
  add(cli::add_roles);
  add(cli::add_validate);
  add(cli::add_simulate);
  add(cli::add_warp);
  add(cli::add_render);
  add(cli::add_run);
  add(cli::add_ports);
  add(cli::add_serve);
  add(cli::add_bench);

  std::vector<std::string> names;
  for (const auto& c : commands) names.push_back(c.first->get_name());
  const std::string unknown =
      cli::unknown_subcommand_message(std::vector<std::string>(argv + 1, argv + argc), {"--threads"}, names);
  if (!unknown.empty()) {
    std::cerr << "pneumo: error: " << unknown << "\n";
    return kExitBadInput;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);   // --help, --version
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }
  if (verbose) log::set_level(log::Level::Debug);
  if (quiet) {
    log::set_level(log::Level::Quiet);
    Progress::set_enabled(false);
  }

  try {
    if (threads_option->count() > 0) set_thread_count(threads);
    for (auto& [sub, run] : commands)
      if (sub->parsed()) return run();
    return kExitBadInput;
  } catch (const InputError& e) {
    std::cerr << "pneumo: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::cerr << "pneumo: error: out of memory\n";
    return kExitFailure;
  } catch (const std::exception& e) {
    std::cerr << "pneumo: failed: " << e.what() << "\n";
    return kExitFailure;
  }
}
