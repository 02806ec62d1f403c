// json_source.h — a small, strict JSON reader whose every value knows where it was written.
//
// Why not nlohmann::json (which the cooker already uses for reports): graph and event files are
// authored by hand, and every mistake in them must be reported as `file:line:col: what is wrong`
// at the value at fault, not at the end of the document. nlohmann::json keeps no positions for
// values (only the parser's error offset), silently keeps the last of two duplicate keys, and its
// ordered_json would still lose where each key was written. This reader keeps, for every value
// and every object key, its line and column, keeps object members in the order written, refuses
// duplicate keys, and says what it expected where the text goes wrong.
//
// Strict RFC 8259: no comments, no trailing commas, no NaN/Infinity, strings in valid UTF-8 with
// the standard escapes (\uXXXX surrogate pairs become UTF-8). A leading UTF-8 byte-order mark is
// skipped. Numbers are doubles (an integer larger than 2^53 loses precision, a number outside the
// double range is an error). Nesting is limited (kMaxDepth) so a hostile file cannot exhaust the
// stack. Lines and columns are 1-based; a column counts characters (UTF-8 code points), a tab is
// one column. Parsing is O(text size); it never throws and never reads outside the text.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::cook::json {

/// Nesting of arrays and objects beyond this is an error.
inline constexpr uint32_t kMaxDepth = 200;

/// Where something was written: 1-based line and column, and the byte offset into the text.
struct Pos {
  uint32_t line = 1;
  uint32_t column = 1;
  uint32_t offset = 0;
};

enum class Type : uint8_t { Null, Bool, Number, String, Array, Object };

/// "null", "a boolean", "a number", "a string", "an array", "an object" (for messages).
const char* type_name(Type type);

struct Member;

/// One JSON value. Only the fields of its type are meaningful.
struct Value {
  Type type = Type::Null;
  Pos pos;  // its first character (the opening quote of a string)
  bool boolean = false;
  double number = 0.0;
  std::string string;           // decoded
  std::vector<Value> items;     // Array
  std::vector<Member> members;  // Object, in the order written, keys unique

  bool is(Type t) const { return type == t; }
  /// The member named key, or null (objects only; O(members)).
  const Value* find(std::string_view key) const;
  /// The member named key (with its key's position), or null.
  const Member* find_member(std::string_view key) const;
};

struct Member {
  std::string key;
  Pos key_pos;  // the key's opening quote
  Value value;
};

/// A parsed document: the root value and the text it came from (kept for string positions).
struct Document {
  std::string file;  // the name messages start with
  std::string text;
  Value root;
};

/// Parses `text`. Errors read `<file>:<line>:<col>: <what>`, e.g.
/// `graph.json:12:5: expected ',' or '}' after an object member`.
Result<Document> parse(std::string_view text, std::string file);

/// `<file>:<line>:<col>: ` for a position.
std::string where(const std::string& file, Pos pos);

/// The position of the character at byte `offset` of the decoded `string` value (a string of
/// `doc`), accounting for escapes in the source text: how errors point inside a string. An
/// offset past the end gives the closing quote's position.
Pos string_position(const Document& doc, const Value& string, size_t offset);

}  // namespace ossa::cook::json
