#pragma once
/// \file The one error type for everything a user can cause, and SPH_CHECK for bugs.

#include <stdexcept>
#include <string>

namespace sph {

/// An error a user can cause (bad scene, bad flag, unwritable path, unstable parameters).
/// `where()` names the origin when known: a file, a key path ("Fluid.stiffness"), a flag.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message, std::string where = {})
      : std::runtime_error(where.empty() ? message : where + ": " + message),
        message_(message),
        where_(std::move(where)) {}

  /// The message without the location.
  const std::string& message() const { return message_; }
  /// The location (file, key path or flag), possibly empty.
  const std::string& where() const { return where_; }

 private:
  std::string message_;
  std::string where_;
};

namespace detail {
[[noreturn]] void check_failed(const char* expr, const char* file, int line, const std::string& msg);
}  // namespace detail

}  // namespace sph

/// Internal invariant (a bug if it fails, never a user error): throws std::logic_error
/// naming the expression, file and line. Always on, also in Release builds.
#define SPH_CHECK(cond, msg)                                                    \
  do {                                                                          \
    if (!(cond)) ::sph::detail::check_failed(#cond, __FILE__, __LINE__, (msg)); \
  } while (false)
