#pragma once
// Result types for fallible calls off the real-time path, and Status for module methods. Asking a
// Result for the value of an error, or for the error of a success, is a broken invariant
// (chimera/core/invariant.hpp): it aborts with a message in every build type.

#include <string>
#include <utility>
#include <variant>

#include "chimera/core/invariant.hpp"

namespace chimera {

/// What kind of failure a Result carries; the message says the rest.
enum class Errc {
  kInvalidInput,  // a file, a parameter or a command that is wrong: the user fixes it
  kNotFound,      // a name that does not exist
  kIllegal,       // a configuration that breaks rule 1, 2 or 3
  kState,         // a signal the lifecycle does not allow in the current state
  kSystem,        // the operating system refused (shm_open, mmap, pthread...)
  kModuleFault,   // a module method failed
};

/// One failure: its kind and a message meant for a person.
struct Error {
  Errc code;
  std::string message;
};

/// A value or an Error. Not real-time safe (the message is a std::string).
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor): returned implicitly
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor): same

  [[nodiscard]] bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & {
    CHIMERA_INVARIANT(ok(), "Result::value() of an error");
    return std::get<0>(v_);
  }
  const T& value() const& {
    CHIMERA_INVARIANT(ok(), "Result::value() of an error");
    return std::get<0>(v_);
  }
  T&& value() && {
    CHIMERA_INVARIANT(ok(), "Result::value() of an error");
    return std::get<0>(std::move(v_));
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  [[nodiscard]] const Error& error() const {
    CHIMERA_INVARIANT(!ok(), "Result::error() of a success");
    return std::get<1>(v_);
  }

 private:
  std::variant<T, Error> v_;
};

/// Success or an Error, for calls with nothing to return.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT(google-explicit-constructor)

  [[nodiscard]] bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  [[nodiscard]] const Error& error() const {
    CHIMERA_INVARIANT(!ok_, "Result<void>::error() of a success");
    return error_;
  }

 private:
  Error error_{Errc::kInvalidInput, {}};
  bool ok_ = true;
};

/// Shorthand for building an Error in a return statement.
inline Error make_error(Errc code, std::string message) { return Error{code, std::move(message)}; }

/// The outcome of a module method. Real-time safe: it carries only a pointer to a string with
/// static storage duration (a literal), never an allocated message.
class [[nodiscard]] Status {
 public:
  static constexpr Status ok() { return Status(nullptr); }
  /// `reason` must outlive the program (a string literal).
  static constexpr Status fail(const char* reason) { return Status(reason ? reason : "failed"); }

  [[nodiscard]] constexpr bool is_ok() const { return reason_ == nullptr; }
  [[nodiscard]] constexpr const char* reason() const { return reason_ ? reason_ : ""; }

 private:
  constexpr explicit Status(const char* reason) : reason_(reason) {}
  const char* reason_;
};

}  // namespace chimera
