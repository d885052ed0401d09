// Error values for bad input. The library never exits the process and never throws across its
// public functions for bad input: it returns an Expected<T> whose error is one line that names
// the file, the item and the problem (docs/scene-format.md, "Errors").
#pragma once

#include <cassert>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace sb {

// What kind of failure; the CLI maps each to an exit code (docs/cli.md).
enum class ErrorKind {
  scene,    // the scene file or something it names is wrong (bad key, unreadable mesh, ...)
  input,    // another input file is wrong (an image given to `compare`, ...)
  output,   // an output could not be written
  internal  // a library failure that is not the user's fault
};

struct Error {
  ErrorKind kind = ErrorKind::scene;
  std::string message;  // one line: "<file>:<line>: <item>: <problem>"
};

inline Error scene_error(std::string message) { return {ErrorKind::scene, std::move(message)}; }
inline Error output_error(std::string message) { return {ErrorKind::output, std::move(message)}; }
inline Error input_error(std::string message) { return {ErrorKind::input, std::move(message)}; }

// A value or an Error. Minimal on purpose: std::expected needs C++23, which Debian 12's GCC only
// has as experimental.
template <class T>
class Expected {
 public:
  Expected(T value) : state_(std::move(value)) {}
  Expected(Error error) : state_(std::move(error)) {}

  bool has_value() const { return state_.index() == 0; }
  explicit operator bool() const { return has_value(); }

  T& value() & {
    assert(has_value());
    return std::get<0>(state_);
  }
  const T& value() const& {
    assert(has_value());
    return std::get<0>(state_);
  }
  T&& value() && {
    assert(has_value());
    return std::get<0>(std::move(state_));
  }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const {
    assert(!has_value());
    return std::get<1>(state_);
  }

 private:
  std::variant<T, Error> state_;
};

// For functions that return nothing but may fail.
struct Ok {};
using Status = Expected<Ok>;

// An invariant whose violation would corrupt memory (an index past a buffer, a transform smaller
// than its kernel) is checked in every build, not only where assert is compiled in: a violation
// throws std::logic_error, which the CLI reports as an internal error (exit code 1) instead of
// writing past an array.
[[noreturn]] inline void invariant_failed(const char* condition, const char* file, int line) {
  throw std::logic_error(std::string("invariant ") + condition + " failed at " + file + ":" +
                         std::to_string(line));
}
#define SB_CHECK(condition) \
  ((condition) ? void(0) : ::sb::invariant_failed(#condition, __FILE__, __LINE__))

}  // namespace sb
