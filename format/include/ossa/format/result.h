// result.h — errors as values, shared by cooker and runtime.
//
// std::expected is C++23 and Debian 12's g++ 12 builds C++20, so this is the small subset ossa
// uses: a value or an Error carrying a message that names the file and what is wrong. Exceptions
// never cross ossa's APIs; a function that can fail returns Result<T> or Status.
#pragma once
#include <string>
#include <utility>
#include <variant>

namespace ossa {

struct Error {
  std::string message;  // "<file>: <what is wrong>", complete enough to show a user as is
};

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}
  Result(Error error) : v_(std::move(error)) {}
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

/// Success, or an Error. Default-constructed = success.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : message_(std::move(error.message)), ok_(false) {}
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const std::string& message() const { return message_; }
  Error error() const { return Error{message_}; }

 private:
  std::string message_;
  bool ok_ = true;
};

}  // namespace ossa
