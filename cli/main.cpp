// The shadowbake command line: each subcommand parses its arguments, calls the library, prints,
// and maps errors to exit codes (docs/cli.md). No algorithm lives here; this file dispatches.
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "formats/output_folder.h"

namespace sbcli {

int exit_code(const sb::Error& e) {
  switch (e.kind) {
    case sb::ErrorKind::scene:
    case sb::ErrorKind::input:
      return bad_input;
    case sb::ErrorKind::output:
      return cannot_write;
    case sb::ErrorKind::internal:
      return internal;
  }
  return internal;
}

int fail(const sb::Error& e) {
  std::fprintf(stderr, "shadowbake: error: %s\n", e.message.c_str());
  return exit_code(e);
}

namespace {

void on_interrupt(int signal) {
  if (!sb::interrupt_output_folders(signal)) return;  // publishing: it re-raises when done
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

}  // namespace

void install_interrupt_handlers() {
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action = {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(signal, &action, nullptr);
  }
}

void reraise_pending_interrupt() {
  if (const int signal = sb::pending_interrupt()) {
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

}  // namespace sbcli

int main(int argc, char** argv) {
  CLI::App app{"shadowbake: bakes soft-shadow lightmaps for area lights (docs/cli.md)"};
  app.set_version_flag("--version", std::string("shadowbake ") + SHADOWBAKE_VERSION);
  app.require_subcommand(1);
  const std::vector<std::pair<std::string, sbcli::Runner>> commands = {
      {"bake", sbcli::add_bake_command(app)},     {"compare", sbcli::add_compare_command(app)},
      {"report", sbcli::add_report_command(app)}, {"plan", sbcli::add_plan_command(app)},
      {"merge", sbcli::add_merge_command(app)},
  };
  sbcli::install_interrupt_handlers();
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error (CLI11's own exit() prints two).
    std::string what = e.what();
    for (char& c : what)
      if (c == '\n' || c == '\r') c = ' ';
    std::fprintf(stderr, "shadowbake: error: %s (shadowbake --help lists the options)\n",
                 what.c_str());
    return sbcli::usage;
  }
  for (const auto& [name, run] : commands) {
    if (!app.got_subcommand(name)) continue;
    try {
      return run();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "shadowbake: error: internal: %s\n", e.what());
      return sbcli::internal;
    }
  }
  return sbcli::usage;
}
