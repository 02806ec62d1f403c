// json_source_test.cpp — the position-keeping JSON reader (cooker/json/json_source.h): values and
// their positions, strictness (each RFC 8259 violation named at its line and column), and
// robustness: every truncation and many byte mutations of a valid file parse or fail cleanly.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "cooker/json/json_check.h"
#include "cooker/json/json_source.h"

namespace json = ossa::cook::json;

namespace {

json::Document ok(std::string_view text) {
  auto doc = json::parse(text, "t.json");
  EXPECT_TRUE(doc.ok()) << (doc.ok() ? "" : doc.error().message);
  return doc.ok() ? std::move(*doc) : json::Document{};
}

std::string err(std::string_view text) {
  auto doc = json::parse(text, "t.json");
  EXPECT_FALSE(doc.ok()) << "parsed: " << text;
  return doc.ok() ? "" : doc.error().message;
}

TEST(JsonSource, ValuesTypesAndOrder) {
  const auto doc = ok(R"({"b": 1, "a": [true, false, null, -2.5e1, "x"], "c": {"z": {}, "y": []}})");
  const json::Value& r = doc.root;
  ASSERT_TRUE(r.is(json::Type::Object));
  ASSERT_EQ(r.members.size(), 3u);
  EXPECT_EQ(r.members[0].key, "b");  // kept in the order written, not sorted
  EXPECT_EQ(r.members[1].key, "a");
  EXPECT_EQ(r.members[2].key, "c");
  EXPECT_EQ(r.find("b")->number, 1.0);
  const json::Value& a = *r.find("a");
  ASSERT_EQ(a.items.size(), 5u);
  EXPECT_TRUE(a.items[0].is(json::Type::Bool) && a.items[0].boolean);
  EXPECT_TRUE(a.items[1].is(json::Type::Bool) && !a.items[1].boolean);
  EXPECT_TRUE(a.items[2].is(json::Type::Null));
  EXPECT_EQ(a.items[3].number, -25.0);
  EXPECT_EQ(a.items[4].string, "x");
  EXPECT_EQ(r.find("c")->members[0].key, "z");
  EXPECT_EQ(r.find("missing"), nullptr);
}

TEST(JsonSource, PositionsOfValuesAndKeys) {
  const auto doc = ok("{\n  \"speed\": 1.5,\n\t\"list\": [1,\n    \"two\"]\n}");
  const json::Member& speed = doc.root.members[0];
  EXPECT_EQ(speed.key_pos.line, 2u);
  EXPECT_EQ(speed.key_pos.column, 3u);
  EXPECT_EQ(speed.value.pos.line, 2u);
  EXPECT_EQ(speed.value.pos.column, 12u);
  const json::Member& list = doc.root.members[1];
  EXPECT_EQ(list.key_pos.line, 3u);
  EXPECT_EQ(list.key_pos.column, 2u);  // a tab is one column
  EXPECT_EQ(list.value.items[1].pos.line, 4u);
  EXPECT_EQ(list.value.items[1].pos.column, 5u);
  EXPECT_EQ(json::where("t.json", list.value.items[1].pos), "t.json:4:5: ");
}

TEST(JsonSource, ColumnsCountCharactersNotBytes) {
  const auto doc = ok("{\"é\": \"ü\", \"x\": 1}");
  EXPECT_EQ(doc.root.members[0].key, "\xC3\xA9");
  EXPECT_EQ(doc.root.members[1].key_pos.column, 12u);  // 2 + "é": 1 column, not 2 bytes
}

TEST(JsonSource, StringEscapes) {
  const auto doc = ok(R"(["a\"b\\c\/d\b\f\n\r\t", "\u00e9\u20AC", "\ud83d\ude00", "\u0041"])");
  EXPECT_EQ(doc.root.items[0].string, "a\"b\\c/d\b\f\n\r\t");
  EXPECT_EQ(doc.root.items[1].string, "\xC3\xA9\xE2\x82\xAC");
  EXPECT_EQ(doc.root.items[2].string, "\xF0\x9F\x98\x80");
  EXPECT_EQ(doc.root.items[3].string, "A");
}

TEST(JsonSource, PositionInsideAString) {
  const auto doc = ok("{\"when\": \"a\\tb && c\"}");
  const json::Value& s = *doc.root.find("when");
  EXPECT_EQ(s.pos.column, 10u);
  EXPECT_EQ(json::string_position(doc, s, 0).column, 11u);   // 'a'
  EXPECT_EQ(json::string_position(doc, s, 1).column, 12u);   // the \t escape
  EXPECT_EQ(json::string_position(doc, s, 2).column, 14u);   // 'b', after the two-character escape
  EXPECT_EQ(json::string_position(doc, s, 7).column, 19u);   // 'c'
  EXPECT_EQ(json::string_position(doc, s, 99).column, 20u);  // past the end: the closing quote
}

TEST(JsonSource, NumbersFollowTheJsonGrammar) {
  const auto doc = ok("[0, -0, 12, 1.25, 1e3, 1E-2, 2.5e+2, 1e-400, 9007199254740993]");
  EXPECT_EQ(doc.root.items[2].number, 12.0);
  EXPECT_EQ(doc.root.items[3].number, 1.25);
  EXPECT_EQ(doc.root.items[4].number, 1000.0);
  EXPECT_EQ(doc.root.items[5].number, 0.01);
  EXPECT_EQ(doc.root.items[6].number, 250.0);
  EXPECT_EQ(doc.root.items[7].number, 0.0);  // underflow to zero
  EXPECT_NE(err("[01]").find("t.json:1:2: invalid number: leading zeros"), std::string::npos);
  EXPECT_NE(err("[1.]").find("t.json:1:2: invalid number: expected a digit after '.'"), std::string::npos);
  EXPECT_NE(err("[-]").find("t.json:1:2: invalid number"), std::string::npos);
  EXPECT_NE(err("[1e]").find("exponent"), std::string::npos);
  EXPECT_NE(err("[+1]").find("t.json:1:2: expected a value, found '+'"), std::string::npos);
  EXPECT_NE(err("[.5]").find("t.json:1:2: expected a value"), std::string::npos);
  EXPECT_NE(err("[1e999]").find("t.json:1:2: number out of range"), std::string::npos);
  EXPECT_NE(err("[NaN]").find("t.json:1:2: expected a value"), std::string::npos);
  EXPECT_NE(err("[Infinity]").find("t.json:1:2: expected a value"), std::string::npos);
}

TEST(JsonSource, SyntaxErrorsSayWhatWasExpectedWhere) {
  EXPECT_EQ(err("{\n  \"a\": 1\n  \"b\": 2\n}"), "t.json:3:3: expected ',' or '}' after an object member, found '\"'");
  EXPECT_EQ(err("[1 2]"), "t.json:1:4: expected ',' or ']' after an array element, found '2'");
  EXPECT_EQ(err("{\"a\" 1}"), "t.json:1:6: expected ':' after the key \"a\"");
  EXPECT_EQ(err("{\"a\": 1,}"), "t.json:1:9: expected a key after ',' (JSON allows no trailing comma)");
  EXPECT_EQ(err("[1,]"), "t.json:1:4: expected a value after ',' (JSON allows no trailing comma)");
  EXPECT_EQ(err("{a: 1}"), "t.json:1:2: expected a string key or '}'");
  EXPECT_EQ(err("['a']"), "t.json:1:2: expected a value; JSON strings use double quotes");
  EXPECT_EQ(err("[\"abc"), "t.json:1:2: unterminated string");
  EXPECT_NE(err("[\"ab\ncd\"]").find("t.json:1:2: unterminated string"), std::string::npos);
  EXPECT_EQ(err("[\"a\\qb\"]"), "t.json:1:4: invalid escape \\q in a string");
  EXPECT_EQ(err("[\"a\\u12G4\"]"), "t.json:1:4: \\u must be followed by four hex digits");
  EXPECT_NE(err("[\"\\ud83d\"]").find("high surrogate"), std::string::npos);
  EXPECT_NE(err("[\"\\ude00\"]").find("lone low surrogate"), std::string::npos);
  EXPECT_EQ(err("[\"a\tb\"]"), "t.json:1:4: control character in a string (write it as an escape)");
  EXPECT_EQ(err("[\"\xC3\x28\"]"), "t.json:1:3: invalid UTF-8 in a string");
  EXPECT_NE(err("[\"\xED\xA0\x80\"]").find("invalid UTF-8"), std::string::npos);  // encoded surrogate
  EXPECT_NE(err("[\"\xC0\xAF\"]").find("invalid UTF-8"), std::string::npos);      // overlong
  EXPECT_EQ(err("[tru]"), "t.json:1:2: invalid literal (expected true, false or null)");
  EXPECT_EQ(err("{} x"), "t.json:1:4: unexpected 'x' after the JSON document");
  EXPECT_EQ(err(""), "t.json:1:1: empty document, expected a JSON value");
  EXPECT_EQ(err("  \n "), "t.json:2:2: empty document, expected a JSON value");
  EXPECT_EQ(err("[1, 2"), "t.json:1:6: expected ',' or ']' after an array element, found the end of the input");
  EXPECT_EQ(err("// comment\n{}"), "t.json:1:1: expected a value, found '/'");
}

TEST(JsonSource, DuplicateKeysAreAnError) {
  EXPECT_EQ(err("{\n  \"speed\": 1,\n  \"speed\": 2\n}"),
            "t.json:3:3: duplicate key \"speed\" (first at line 2, column 3)");
  // The same key in different objects is fine.
  ok(R"({"a": {"x": 1}, "b": {"x": 2}})");
}

TEST(JsonSource, NestingIsBounded) {
  const std::string deep_ok = std::string(json::kMaxDepth, '[') + std::string(json::kMaxDepth, ']');
  ok(deep_ok);
  const std::string too_deep(100000, '[');
  EXPECT_NE(err(too_deep).find("nesting deeper than"), std::string::npos);
  std::string objects;
  for (int i = 0; i < 1000; ++i) objects += "{\"a\":";
  EXPECT_NE(err(objects).find("nesting deeper than"), std::string::npos);
}

TEST(JsonSource, ByteOrderMarkIsSkipped) {
  const auto doc = ok("\xEF\xBB\xBF{\"a\": 1}");
  EXPECT_EQ(doc.root.members[0].key_pos.column, 2u);
}

const char* kSample = R"({
  "ossa_graph": 1,
  "name": "pab \u00e9\n é",
  "clips": {"walk": "walk.fbx", "run": {"source": "run.fbx", "events": [{"name": "foot", "time": 0.25}]}},
  "parameters": {"speed": {"type": "float", "default": -1.5e-1, "min": 0, "max": 6}, "b": {"type": "bool",
    "default": true}},
  "root": {"blend": [{"clip": "walk"}, {"clip": "run"}], "alpha": "speed", "x": [null, [], {}, 0.5e2]}
})";

TEST(JsonSource, EveryTruncationFailsCleanly) {
  const std::string text = kSample;
  ok(text);
  for (size_t n = 0; n < text.size(); ++n) {
    auto doc = json::parse(std::string_view(text).substr(0, n), "cut.json");
    // The document closes only at its last '}': every shorter prefix is an error at a position.
    ASSERT_FALSE(doc.ok()) << "prefix of " << n << " bytes parsed";
    EXPECT_EQ(doc.error().message.rfind("cut.json:", 0), 0u) << doc.error().message;
  }
}

TEST(JsonSource, MutatedBytesNeverCrash) {
  const std::string text = kSample;
  uint64_t state = 0x9E3779B97F4A7C15ull;
  const auto next = [&] {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
  };
  const char interesting[] = {'{', '}', '[', ']', ',', ':',  '"',    '\\',   'u',
                              '0', '-', 'e', '.', ' ', '\n', '\x80', '\xff', 't'};
  size_t parsed = 0;
  for (int round = 0; round < 20000; ++round) {
    std::string m = text;
    const int edits = 1 + static_cast<int>(next() % 4);
    for (int e = 0; e < edits; ++e) {
      const size_t at = next() % m.size();
      switch (next() % 3) {
        case 0: m[at] = interesting[next() % sizeof interesting]; break;
        case 1: m.erase(at, 1 + next() % 3); break;
        default: m.insert(at, 1, interesting[next() % sizeof interesting]); break;
      }
      if (m.empty()) m = "x";
    }
    auto doc = json::parse(m, "m.json");
    if (doc.ok()) ++parsed;
    else ASSERT_EQ(doc.error().message.rfind("m.json:", 0), 0u) << doc.error().message;
  }
  EXPECT_GT(parsed, 0u);  // some mutations keep it valid (a space for a space...)
}

TEST(JsonCheck, TypoHintsAndAllowedKeys) {
  auto doc = json::parse(R"({"blendtime": 1, "select": "x", "Children": []})", "k.json");
  ASSERT_TRUE(doc.ok());
  json::Checker check(*doc);
  EXPECT_FALSE(check.expect_keys(doc->root, {"select", "children", "blend_time", "name"}, "a select node"));
  ASSERT_EQ(check.errors().size(), 2u);
  EXPECT_EQ(check.errors()[0],
            "k.json:1:2: unknown key \"blendtime\" in a select node (did you mean \"blend_time\"?); allowed keys: "
            "select, children, blend_time, name");
  EXPECT_NE(
      check.errors()[1].find("k.json:1:33: unknown key \"Children\" in a select node (did you mean \"children\"?)"),
      std::string::npos);
  EXPECT_EQ(ossa::cook::json::closest_name("zzz", std::vector<std::string>{"speed", "crossed"}), "");
}

TEST(JsonCheck, TypeAndNumberChecks) {
  auto doc = json::parse(R"({"a": "s", "b": 1.5, "c": 7})", "n.json");
  ASSERT_TRUE(doc.ok());
  json::Checker check(*doc);
  long long i = 0;
  EXPECT_FALSE(check.expect(*doc->root.find("a"), json::Type::Number, "\"a\""));
  EXPECT_FALSE(check.expect_integer(*doc->root.find("b"), "\"b\"", 0, 10, &i));
  EXPECT_FALSE(check.expect_integer(*doc->root.find("c"), "\"c\"", 0, 5, &i));
  EXPECT_TRUE(check.expect_integer(*doc->root.find("c"), "\"c\"", 0, 10, &i));
  EXPECT_EQ(i, 7);
  ASSERT_EQ(check.errors().size(), 3u);
  EXPECT_EQ(check.errors()[0], "n.json:1:7: \"a\" must be a number, not a string");
  EXPECT_EQ(check.errors()[1], "n.json:1:17: \"b\" must be a whole number");
  EXPECT_EQ(check.errors()[2], "n.json:1:27: \"c\" must be within [0, 5]");
}

}  // namespace
