// bad_input.h — what the bad-input suite's files share: a file must be rejected with a message
// that names it and says what is wrong (checked by distinctive words, case-insensitively, so
// wording can improve without breaking tests), and a damaged file that is accepted must be safe
// to walk. See bad_input_test.cpp for the suite; the cases are split by what they break:
// bad_input_test.cpp (damaged bytes, not an .ossa file, hostile names), bad_input_mesh_test.cpp
// (skeleton, mesh and morph invariants), bad_input_clip_test.cpp (clip and texture invariants).
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "asset_walk.h"
#include <ossa/loader/asset.h>
#include "test_files.h"

namespace ossa::test {

using Keywords = std::vector<std::vector<std::string>>;  // every group must match; any word of a group

inline std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

inline bool contains_any(const std::string& message, const std::vector<std::string>& words) {
  const std::string m = lower(message);
  return std::any_of(words.begin(), words.end(),
                     [&](const std::string& w) { return m.find(lower(w)) != std::string::npos; });
}

inline std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "\"" : " | \"") + w + "\"";
  return out;
}

// A message that names the file and says what is wrong.
inline ::testing::AssertionResult explains(const std::string& message, const std::string& name,
                                           const Keywords& groups) {
  if (message.empty()) return ::testing::AssertionFailure() << "empty error message";
  if (message.find(name) == std::string::npos)
    return ::testing::AssertionFailure() << "message does not name \"" << name << "\": " << message;
  for (const auto& group : groups)
    if (!contains_any(message, group))
      return ::testing::AssertionFailure() << "message mentions none of " << join(group) << ": " << message;
  return ::testing::AssertionSuccess() << message;
}

inline ::testing::AssertionResult rejected(const Result<Asset>& result, const std::string& name,
                                           const Keywords& groups) {
  if (result.ok()) return ::testing::AssertionFailure() << name << " was accepted";
  return explains(result.error().message, name, groups);
}

inline std::string current_test_file_name() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return std::string(info->test_suite_name()) + "." + info->name() + ".ossa";
}

// Both entry points over the same bytes must reject them and explain why.
inline ::testing::AssertionResult rejects(const std::vector<uint8_t>& bytes, const Keywords& groups) {
  const std::string name = current_test_file_name();
  auto loaded = rejected(Asset::from_bytes(bytes, name), name, groups);
  if (!loaded) return ::testing::AssertionFailure() << "Asset::from_bytes: " << loaded.message();
  const AlignedBytes aligned(bytes);
  const Status status = verify_buffer(aligned.span(), name);
  if (status.ok()) return ::testing::AssertionFailure() << "verify_buffer accepted what from_bytes rejected";
  auto verified = explains(status.message(), name, groups);
  if (!verified) return ::testing::AssertionFailure() << "verify_buffer: " << verified.message();
  return ::testing::AssertionSuccess() << loaded.message();
}

inline ::testing::AssertionResult rejects(const SyntheticSpec& spec, const Keywords& groups) {
  return rejects(make_valid_file(spec), groups);
}

inline ::testing::AssertionResult accepts(const std::vector<uint8_t>& bytes) {
  const std::string name = current_test_file_name();
  const Result<Asset> asset = Asset::from_bytes(bytes, name);
  if (!asset) return ::testing::AssertionFailure() << "rejected: " << asset.error().message;
  const std::string problem = walk_asset(*asset);
  if (!problem.empty()) return ::testing::AssertionFailure() << "accepted, but " << problem;
  const AlignedBytes aligned(bytes);
  const Status status = verify_buffer(aligned.span(), name);
  if (!status) return ::testing::AssertionFailure() << "verify_buffer rejected: " << status.message();
  return ::testing::AssertionSuccess();
}

inline const Keywords kMesh = {{"body", "mesh 0", "mesh[0]", "meshes[0]"}};
inline const Keywords kClip = {{"walk", "clip 0", "clip[0]", "clips[0]"}};

inline Keywords with(Keywords base, std::vector<std::string> words) {
  base.push_back(std::move(words));
  return base;
}
inline Keywords with(Keywords base, std::vector<std::string> words, std::vector<std::string> more) {
  base.push_back(std::move(words));
  base.push_back(std::move(more));
  return base;
}

inline constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
inline constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace ossa::test
