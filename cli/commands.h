// What every shadowbake subcommand shares: exit codes, error printing, and the way a command
// registers itself (one file per command; main.cpp only dispatches).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

#include "core/error.h"

namespace sbcli {

// Exit codes, documented in docs/cli.md.
enum Exit : int {
  ok = 0,
  internal = 1,
  usage = 2,
  bad_input = 3,
  cannot_write = 4,
  gate_failed = 5
};

// The exit code for a library error.
int exit_code(const sb::Error& e);
// Prints "shadowbake: error: <message>" on stderr and returns exit_code(e).
int fail(const sb::Error& e);

// SIGINT, SIGTERM and SIGHUP remove the staging folder of an open sb::OutputFolder before they
// end the process; one that arrives while the folder publishes ends it once publishing is done,
// which reraise_pending_interrupt (called after publishing) sees to.
void install_interrupt_handlers();
void reraise_pending_interrupt();

// A command adds its subcommand and options to the app and returns what to run once the command
// line has parsed; that returns the exit code.
using Runner = std::function<int()>;

Runner add_bake_command(CLI::App& app);     // bake_command.cpp
Runner add_compare_command(CLI::App& app);  // compare_command.cpp
Runner add_report_command(CLI::App& app);   // report_command.cpp
Runner add_plan_command(CLI::App& app);     // plan_command.cpp
Runner add_merge_command(CLI::App& app);    // merge_command.cpp

}  // namespace sbcli
