// json_check.cpp — value checks with positioned messages (json_check.h).
#include "cooker/json/json_check.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "common/edit_distance.h"

namespace ossa::cook::json {

std::string Checker::message() const {
  std::vector<size_t> order(errors_.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return positions_[a].offset < positions_[b].offset; });
  std::string out;
  for (size_t i : order) out += (out.empty() ? "" : "\n") + errors_[i];
  if (dropped_ > 0) out += "\n" + doc_.file + ": " + std::to_string(dropped_) + " more problems not shown";
  return out;
}

bool Checker::error(Pos pos, const std::string& what) {
  std::string message = where(doc_.file, pos) + what;
  // A named node used twice is checked twice: say each problem once.
  if (std::find(errors_.begin(), errors_.end(), message) != errors_.end()) return false;
  if (errors_.size() < kMaxErrors) {
    errors_.push_back(std::move(message));
    positions_.push_back(pos);
  } else {
    ++dropped_;
  }
  return false;
}

bool Checker::error_in_string(const Value& string, size_t offset, const std::string& what) {
  return error(string_position(doc_, string, offset), what);
}

bool Checker::expect(const Value& v, Type t, std::string_view what) {
  if (v.type == t) return true;
  return error(v.pos, std::string(what) + " must be " + type_name(t) + ", not " + type_name(v.type));
}

namespace {

std::string folded(std::string_view s) {
  std::string out;
  for (char c : s)
    if (c != '_' && c != '-' && c != ' ') out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

std::string closest_name(std::string_view key, const std::vector<std::string_view>& candidates) {
  std::string_view best;
  size_t best_distance = 3;
  const std::string key_folded = folded(key);
  for (std::string_view a : candidates) {
    if (folded(a) == key_folded) return std::string(a);
  }
  for (std::string_view a : candidates) {
    // "looping" for "loop", "blend" for "blend_time": one name extends the other.
    const std::string af = folded(a);
    const size_t shorter = std::min(af.size(), key_folded.size());
    if (shorter >= 3 && af.compare(0, shorter, key_folded, 0, shorter) == 0) return std::string(a);
  }
  for (std::string_view a : candidates) {
    const size_t d = edit_distance(key, a);
    if (d < best_distance && d < a.size() && d < key.size()) {
      best_distance = d;
      best = a;
    }
  }
  return std::string(best);
}

std::string closest_name(std::string_view key, const std::vector<std::string>& candidates) {
  return closest_name(key, std::vector<std::string_view>(candidates.begin(), candidates.end()));
}

bool Checker::expect_keys(const Value& object, std::initializer_list<std::string_view> allowed, std::string_view what) {
  if (object.type != Type::Object) return false;
  bool ok = true;
  for (const Member& m : object.members) {
    if (std::find(allowed.begin(), allowed.end(), m.key) != allowed.end()) continue;
    std::string list;
    for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    const std::string hint = closest_name(m.key, std::vector<std::string_view>(allowed));
    ok = error(m.key_pos, "unknown key \"" + m.key + "\" in " + std::string(what) +
                              (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") + "; allowed keys: " + list);
  }
  return ok;
}

bool Checker::expect_number(const Value& v, std::string_view what, double* out) {
  if (!expect(v, Type::Number, what)) return false;
  if (!std::isfinite(v.number)) return error(v.pos, std::string(what) + " must be a finite number");
  *out = v.number;
  return true;
}

bool Checker::expect_integer(const Value& v, std::string_view what, long long lo, long long hi, long long* out) {
  double d = 0.0;
  if (!expect_number(v, what, &d)) return false;
  if (d != std::floor(d)) return error(v.pos, std::string(what) + " must be a whole number");
  if (d < static_cast<double>(lo) || d > static_cast<double>(hi))
    return error(v.pos, std::string(what) + " must be within [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  *out = static_cast<long long>(d);
  return true;
}

bool Checker::expect_name(const Value& v, std::string_view what, std::string* out) {
  if (!expect(v, Type::String, what)) return false;
  if (v.string.empty()) return error(v.pos, std::string(what) + " must not be empty");
  *out = v.string;
  return true;
}

}  // namespace ossa::cook::json
