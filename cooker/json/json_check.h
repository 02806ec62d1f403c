// json_check.h — checking hand-written JSON (graph files, event sidecars) against what is
// expected, collecting every problem as `file:line:col: message`.
//
// The graph compiler and the event-sidecar reader both need the same small set of checks (a
// value's type, an object's allowed keys with a "did you mean" for typos, finite and integer
// numbers) and both want to report all problems of a file in one go rather than one per cook.
// Checks return whether the value was usable, so callers skip what depends on a bad value and one
// mistake does not cascade into several messages.
#pragma once
#include <cstddef>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "cooker/json/json_source.h"

namespace ossa::cook::json {

class Checker {
 public:
  /// At most this many messages are kept; the last then says more were left out.
  static constexpr size_t kMaxErrors = 50;

  explicit Checker(const Document& doc) : doc_(doc) {}

  const Document& doc() const { return doc_; }
  bool ok() const { return errors_.empty(); }
  /// True once kMaxErrors messages are kept: a further one is only counted, so a caller may skip
  /// what makes a message costly (a hint searched among thousands of names, a list of them).
  bool full() const { return errors_.size() >= kMaxErrors; }
  /// The messages in the order found.
  const std::vector<std::string>& errors() const { return errors_; }
  /// Every message, one per line, in the order of their positions in the file.
  std::string message() const;

  /// Records `file:line:col: what`. Always returns false (for `return checker.error(...)`).
  bool error(Pos pos, const std::string& what);
  /// An error at character `offset` of a string value (json::string_position).
  bool error_in_string(const Value& string, size_t offset, const std::string& what);

  /// True when v has type t; otherwise records "<what> must be <t>, not <v's type>".
  bool expect(const Value& v, Type t, std::string_view what);
  /// For an object: records one error per key not in `allowed`, naming the allowed keys and the
  /// closest one when a key looks like a typo of it. True when every key is allowed.
  bool expect_keys(const Value& object, std::initializer_list<std::string_view> allowed, std::string_view what);
  /// A finite number.
  bool expect_number(const Value& v, std::string_view what, double* out);
  /// A number with no fractional part, within [lo, hi].
  bool expect_integer(const Value& v, std::string_view what, long long lo, long long hi, long long* out);
  /// A non-empty string.
  bool expect_name(const Value& v, std::string_view what, std::string* out);

 private:
  const Document& doc_;
  std::vector<std::string> errors_;
  std::vector<Pos> positions_;  // of errors_
  size_t dropped_ = 0;
};

/// The candidate closest to `key` (equal ignoring case and '_', or within edit distance 2), or
/// "" when none is close: the "did you mean" of messages.
std::string closest_name(std::string_view key, const std::vector<std::string_view>& candidates);
std::string closest_name(std::string_view key, const std::vector<std::string>& candidates);

}  // namespace ossa::cook::json
