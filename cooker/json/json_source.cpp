// json_source.cpp — the strict, position-keeping JSON reader (json_source.h).
//
// A hand-written recursive-descent parser over the RFC 8259 grammar. It stops at the first
// syntax error (a later "error" would only be a consequence of the first) and says what it
// expected there. Numbers are checked against the JSON grammar here and converted with
// std::from_chars, which is locale-independent and exact.
#include "cooker/json/json_source.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <limits>
#include <map>

namespace ossa::cook::json {

const char* type_name(Type type) {
  switch (type) {
    case Type::Null: return "null";
    case Type::Bool: return "a boolean";
    case Type::Number: return "a number";
    case Type::String: return "a string";
    case Type::Array: return "an array";
    case Type::Object: return "an object";
  }
  return "a value";
}

const Member* Value::find_member(std::string_view key) const {
  for (const Member& m : members)
    if (m.key == key) return &m;
  return nullptr;
}

const Value* Value::find(std::string_view key) const {
  const Member* m = find_member(key);
  return m ? &m->value : nullptr;
}

std::string where(const std::string& file, Pos pos) {
  return file + ":" + std::to_string(pos.line) + ":" + std::to_string(pos.column) + ": ";
}

namespace {

bool is_continuation(unsigned char c) { return (c & 0xC0u) == 0x80u; }

void append_utf8(std::string& out, uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

/// Length of the well-formed UTF-8 sequence starting at s[i] (a byte >= 0x80), or 0 when it is
/// not well formed (bad lead, missing continuation, overlong, surrogate, above U+10FFFF).
size_t utf8_sequence(std::string_view s, size_t i) {
  const auto b = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  size_t len = 0;
  uint32_t cp = 0, min = 0;
  if (c >= 0xC2 && c <= 0xDF) len = 2, cp = c & 0x1Fu, min = 0x80;
  else if (c >= 0xE0 && c <= 0xEF) len = 3, cp = c & 0x0Fu, min = 0x800;
  else if (c >= 0xF0 && c <= 0xF4) len = 4, cp = c & 0x07u, min = 0x10000;
  else return 0;
  if (i + len > s.size()) return 0;
  for (size_t k = 1; k < len; ++k) {
    if (!is_continuation(b(i + k))) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3Fu);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return len;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// Four hex digits at s[i..i+4) as a code unit, or -1.
int32_t hex4(std::string_view s, size_t i) {
  if (i + 4 > s.size()) return -1;
  int32_t v = 0;
  for (size_t k = 0; k < 4; ++k) {
    const int d = hex_digit(s[i + k]);
    if (d < 0) return -1;
    v = v * 16 + d;
  }
  return v;
}

std::string describe_char(std::string_view s, size_t i) {
  if (i >= s.size()) return "the end of the input";
  const unsigned char c = static_cast<unsigned char>(s[i]);
  if (c >= 0x20 && c < 0x7F) return std::string("'") + static_cast<char>(c) + "'";
  char buf[16];
  std::snprintf(buf, sizeof buf, "byte 0x%02X", c);
  return buf;
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& file) : s_(text), file_(file) {}

  Result<Value> run() {
    if (s_.size() >= 3 && s_.substr(0, 3) == "\xEF\xBB\xBF") {
      i_ = 3;  // byte-order mark: not part of the text's columns
    }
    skip_ws();
    if (i_ >= s_.size()) return fail_here("empty document, expected a JSON value");
    Value root;
    if (!value(root, 0)) return Error{error_};
    skip_ws();
    if (i_ < s_.size()) return fail_here("unexpected " + describe_char(s_, i_) + " after the JSON document");
    return root;
  }

 private:
  std::string_view s_;
  const std::string& file_;
  size_t i_ = 0;
  Pos pos_{1, 1, 0};  // position of s_[i_]
  std::string error_;

  Pos here() const {
    Pos p = pos_;
    p.offset = static_cast<uint32_t>(i_);
    return p;
  }

  bool fail(Pos at, const std::string& what) {
    error_ = where(file_, at) + what;
    return false;
  }
  Error fail_here(const std::string& what) {
    fail(here(), what);
    return Error{error_};
  }

  void bump() {
    const char c = s_[i_++];
    if (c == '\n') {
      ++pos_.line;
      pos_.column = 1;
    } else if (i_ >= s_.size() || !is_continuation(static_cast<unsigned char>(s_[i_]))) {
      ++pos_.column;
    }
  }
  void bump(size_t n) {
    for (size_t k = 0; k < n; ++k) bump();
  }

  void skip_ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) bump();
  }

  bool value(Value& out, uint32_t depth) {
    out.pos = here();
    if (i_ >= s_.size()) return fail(here(), "unexpected end of input, expected a value");
    const char c = s_[i_];
    switch (c) {
      case '{': return object(out, depth + 1);
      case '[': return array(out, depth + 1);
      case '"': out.type = Type::String; return string(out.string);
      case 't': return literal(out, "true", Type::Bool, true);
      case 'f': return literal(out, "false", Type::Bool, false);
      case 'n': return literal(out, "null", Type::Null, false);
      default: break;
    }
    if (c == '-' || (c >= '0' && c <= '9')) return number(out);
    if (c == '\'') return fail(here(), "expected a value; JSON strings use double quotes");
    return fail(here(), "expected a value, found " + describe_char(s_, i_));
  }

  bool literal(Value& out, std::string_view word, Type type, bool b) {
    if (s_.substr(i_, word.size()) != word) return fail(here(), "invalid literal (expected true, false or null)");
    bump(word.size());
    out.type = type;
    out.boolean = b;
    return true;
  }

  bool object(Value& out, uint32_t depth) {
    if (depth > kMaxDepth) return fail(here(), "nesting deeper than " + std::to_string(kMaxDepth) + " levels");
    out.type = Type::Object;
    bump();  // {
    skip_ws();
    if (i_ < s_.size() && s_[i_] == '}') {
      bump();
      return true;
    }
    std::map<std::string, Pos, std::less<>> seen;
    for (bool after_comma = false;; after_comma = true) {
      if (i_ >= s_.size() || s_[i_] != '"') {
        if (after_comma && i_ < s_.size() && s_[i_] == '}')
          return fail(here(), "expected a key after ',' (JSON allows no trailing comma)");
        return fail(here(), after_comma ? "expected a string key after ','" : "expected a string key or '}'");
      }
      Member m;
      m.key_pos = here();
      if (!string(m.key)) return false;
      if (auto [it, inserted] = seen.emplace(m.key, m.key_pos); !inserted) {
        return fail(m.key_pos, "duplicate key \"" + m.key + "\" (first at line " + std::to_string(it->second.line) +
                                   ", column " + std::to_string(it->second.column) + ")");
      }
      skip_ws();
      if (i_ >= s_.size() || s_[i_] != ':') return fail(here(), "expected ':' after the key \"" + m.key + "\"");
      bump();
      skip_ws();
      if (!value(m.value, depth)) return false;
      out.members.push_back(std::move(m));
      skip_ws();
      if (i_ < s_.size() && s_[i_] == ',') {
        bump();
        skip_ws();
        continue;
      }
      if (i_ < s_.size() && s_[i_] == '}') {
        bump();
        return true;
      }
      return fail(here(), "expected ',' or '}' after an object member, found " + describe_char(s_, i_));
    }
  }

  bool array(Value& out, uint32_t depth) {
    if (depth > kMaxDepth) return fail(here(), "nesting deeper than " + std::to_string(kMaxDepth) + " levels");
    out.type = Type::Array;
    bump();  // [
    skip_ws();
    if (i_ < s_.size() && s_[i_] == ']') {
      bump();
      return true;
    }
    for (;;) {
      if (i_ < s_.size() && s_[i_] == ']')
        return fail(here(), "expected a value after ',' (JSON allows no trailing comma)");
      Value item;
      if (!value(item, depth)) return false;
      out.items.push_back(std::move(item));
      skip_ws();
      if (i_ < s_.size() && s_[i_] == ',') {
        bump();
        skip_ws();
        continue;
      }
      if (i_ < s_.size() && s_[i_] == ']') {
        bump();
        return true;
      }
      return fail(here(), "expected ',' or ']' after an array element, found " + describe_char(s_, i_));
    }
  }

  bool string(std::string& out) {
    const Pos open = here();
    bump();  // "
    for (;;) {
      if (i_ >= s_.size()) return fail(open, "unterminated string");
      const unsigned char c = static_cast<unsigned char>(s_[i_]);
      if (c == '"') {
        bump();
        return true;
      }
      if (c == '\n') return fail(open, "unterminated string (a line break inside a string must be written \\n)");
      if (c < 0x20) return fail(here(), "control character in a string (write it as an escape)");
      if (c == '\\') {
        if (!escape(out)) return false;
        continue;
      }
      if (c < 0x80) {
        out += static_cast<char>(c);
        bump();
        continue;
      }
      const size_t len = utf8_sequence(s_, i_);
      if (len == 0) return fail(here(), "invalid UTF-8 in a string");
      out.append(s_.substr(i_, len));
      bump(len);
    }
  }

  bool escape(std::string& out) {
    const Pos at = here();
    if (i_ + 1 >= s_.size()) return fail(at, "unterminated string");
    const char e = s_[i_ + 1];
    char plain = 0;
    switch (e) {
      case '"': plain = '"'; break;
      case '\\': plain = '\\'; break;
      case '/': plain = '/'; break;
      case 'b': plain = '\b'; break;
      case 'f': plain = '\f'; break;
      case 'n': plain = '\n'; break;
      case 'r': plain = '\r'; break;
      case 't': plain = '\t'; break;
      case 'u': break;
      default: return fail(at, "invalid escape \\" + std::string(1, e) + " in a string");
    }
    if (e != 'u') {
      out += plain;
      bump(2);
      return true;
    }
    const int32_t unit = hex4(s_, i_ + 2);
    if (unit < 0) return fail(at, "\\u must be followed by four hex digits");
    uint32_t cp = static_cast<uint32_t>(unit);
    size_t consumed = 6;
    if (cp >= 0xDC00 && cp <= 0xDFFF) return fail(at, "\\u escape is a lone low surrogate");
    if (cp >= 0xD800 && cp <= 0xDBFF) {
      const int32_t low = (i_ + 7 < s_.size() && s_[i_ + 6] == '\\' && s_[i_ + 7] == 'u') ? hex4(s_, i_ + 8) : -1;
      if (low < 0xDC00 || low > 0xDFFF) return fail(at, "\\u escape is a high surrogate without its low surrogate");
      cp = 0x10000 + ((cp - 0xD800) << 10) + (static_cast<uint32_t>(low) - 0xDC00);
      consumed = 12;
    }
    append_utf8(out, cp);
    bump(consumed);
    return true;
  }

  bool number(Value& out) {
    const Pos start = here();
    const size_t begin = i_;
    auto digit = [&](size_t k) { return k < s_.size() && s_[k] >= '0' && s_[k] <= '9'; };
    size_t k = i_;
    if (s_[k] == '-') ++k;
    if (!digit(k)) return fail(start, "invalid number: expected a digit");
    if (s_[k] == '0') {
      ++k;
      if (digit(k)) return fail(start, "invalid number: leading zeros are not allowed");
    } else {
      while (digit(k)) ++k;
    }
    if (k < s_.size() && s_[k] == '.') {
      ++k;
      if (!digit(k)) return fail(start, "invalid number: expected a digit after '.'");
      while (digit(k)) ++k;
    }
    bool negative_exponent = false;
    if (k < s_.size() && (s_[k] == 'e' || s_[k] == 'E')) {
      ++k;
      if (k < s_.size() && (s_[k] == '+' || s_[k] == '-')) negative_exponent = s_[k++] == '-';
      if (!digit(k)) return fail(start, "invalid number: expected a digit in the exponent");
      while (digit(k)) ++k;
    }
    double v = 0.0;
    const char* first = s_.data() + begin;
    const char* last = s_.data() + k;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec == std::errc::result_out_of_range) {
      if (!negative_exponent) return fail(start, "number out of range");
      v = 0.0;  // underflow: a value closer to zero than any double is zero
    } else if (ec != std::errc() || ptr != last) {
      return fail(start, "invalid number");
    }
    out.type = Type::Number;
    out.number = v;
    bump(k - begin);
    return true;
  }
};

}  // namespace

Result<Document> parse(std::string_view text, std::string file) {
  if (text.size() > std::numeric_limits<uint32_t>::max() / 2)
    return Error{file + ": too large for a JSON source file (" + std::to_string(text.size()) + " bytes)"};
  Document doc;
  doc.file = std::move(file);
  doc.text = std::string(text);
  Parser parser(doc.text, doc.file);
  Result<Value> root = parser.run();
  if (!root) return root.error();
  doc.root = std::move(*root);
  return doc;
}

Pos string_position(const Document& doc, const Value& string, size_t offset) {
  const std::string_view s = doc.text;
  Pos pos = string.pos;
  size_t i = string.pos.offset;
  if (string.type != Type::String || i >= s.size() || s[i] != '"') return pos;
  ++i;
  ++pos.column;
  size_t decoded = 0;
  while (i < s.size() && s[i] != '"') {
    size_t raw = 1, out = 1, columns = 1;
    if (s[i] == '\\' && i + 1 < s.size()) {
      raw = 2;
      if (s[i + 1] == 'u') {
        const int32_t unit = hex4(s, i + 2);
        raw = 6;
        out = unit < 0x80 ? 1 : unit < 0x800 ? 2 : 3;
        if (unit >= 0xD800 && unit <= 0xDBFF) raw = 12, out = 4;
      }
      columns = raw;
    } else if (static_cast<unsigned char>(s[i]) >= 0x80) {
      raw = out = std::max<size_t>(1, utf8_sequence(s, i));
    }
    if (decoded + out > offset) break;
    decoded += out;
    i += raw;
    pos.column += static_cast<uint32_t>(columns);
  }
  pos.offset = static_cast<uint32_t>(std::min(i, s.size()));
  return pos;
}

}  // namespace ossa::cook::json
