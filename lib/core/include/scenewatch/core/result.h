#pragma once
/// Result<T>: a value or an Error naming what went wrong. Bad input from outside (files, network,
/// config) is returned this way; library code never prints and never throws for it.
#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace scenewatch {

/// Broad class of an error; the service maps it onto its status codes.
enum class ErrorCode {
  kInvalidArgument,   ///< malformed or inconsistent input
  kNotFound,          ///< file, object or key does not exist
  kIoError,           ///< the operating system refused a read or write
  kPermissionDenied,  ///< outside the configured roots
  kUnavailable,       ///< busy or shutting down
  kInternal,          ///< a bug; should not happen
};

/// Printable name of an error code ("invalid_argument", ...).
const char* to_string(ErrorCode code);

/// An error with a message that names the file, key or field and the problem.
struct Error {
  ErrorCode code = ErrorCode::kInvalidArgument;
  std::string message;
};

/// Shorthand constructors.
inline Error invalid_argument(std::string msg) { return {ErrorCode::kInvalidArgument, std::move(msg)}; }
inline Error not_found(std::string msg) { return {ErrorCode::kNotFound, std::move(msg)}; }
inline Error io_error(std::string msg) { return {ErrorCode::kIoError, std::move(msg)}; }

/// A value of type T or an Error.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : data_(std::move(value)) {}  // NOLINT: implicit on purpose
  Result(Error error) : data_(std::move(error)) {}  // NOLINT

  bool ok() const { return std::holds_alternative<T>(data_); }
  explicit operator bool() const { return ok(); }

  const T& value() const& { assert(ok()); return std::get<T>(data_); }
  T& value() & { assert(ok()); return std::get<T>(data_); }
  T&& value() && { assert(ok()); return std::get<T>(std::move(data_)); }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

  const Error& error() const { assert(!ok()); return std::get<Error>(data_); }

 private:
  std::variant<T, Error> data_;
};

/// Result of an operation without a value.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const { assert(!ok_); return error_; }

 private:
  Error error_;
  bool ok_ = true;
};

using Status = Result<void>;

}  // namespace scenewatch
