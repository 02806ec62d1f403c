// clip_compress_share.cpp — step 7 of the clip compressor (the design is in clip_compress.cpp's
// header): key-frame lists shared between animated channels.
//
// Why. Each animated channel's keys are chosen on its own (step 5), so a clip whose channels all
// drop keys has one key-frame list per channel: Pab's crossarms, 56 lists for 56 channels. The
// format lets channels share one list (format/ossa.fbs, AnimatedChannel), and a runtime tests and
// moves one cursor per list (runtime/anim/sample.cpp: a run), so every list costs each sample a
// compare and each crossing a cursor move, and costs the file 16 bits per key.
//
// How. Groups start as the channels with identical lists. The merge of two groups is one list for
// all their channels, made by the same greedy key removal as a channel's own (reduce_keys over
// every member at once: a segment is kept only where every member stays within its own budget at
// every position), so the merged list keeps each channel within the bound its own list kept. A
// group of K keys whose channels store B bits per key costs K * (16 + B) bits, and a merge is
// credited kRunBits for the list it removes; the pair whose merge saves the most merges first, and
// merging stops when no merge saves anything: a list is shared where its extra keys cost less than
// the key frames (and the list) they save. Channels keyed at every frame are one group from the
// start (pack shares their list).
//
// Members keep their codes at every frame (ChannelPlan::codes), so a channel takes any list
// without its keys being chosen again. Compensation (step 4) saw each parent's own list, so the
// caller (clip_compress.cpp) fits every channel again, parents first, to its target given its
// parents as now decoded, keeping its list and bits, and verifies the clip; a joint over the bound
// takes its chain out of sharing, and after kMaxShareRounds the clip keeps its own lists.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <span>
#include <vector>

#include "cooker/clip/clip_compress_internal.h"
#include <ossa/format/clip_codec.h>

namespace ossa::cook::compress_detail {
namespace {

constexpr uint64_t kKeyFrameBits = 16;
// What one list fewer is worth, in bits of the file: a runtime tests every list at every sample and
// moves its cursor at each of its keys. On Pab's crossarms (56 lists) a merge counted at 0 / 400 /
// 2000 bits per list leaves 38 / 21 / 11 lists and 30424 / 29448 / 31035 bytes (31763 unshared),
// and the montage's sample costs about 0.55k / 1.15k / 1.3k fewer instructions per update
// (callgrind, ossa-bench-graph-updates --montage); 400 keeps the file smallest.
constexpr int64_t kRunBits = 400;
// Groups beyond which a clip keeps its own lists: the pairs are O(groups^2) in memory and key
// removals (the shared assets have at most 56; a rig of hundreds of joints all dropping keys would
// otherwise cost its cook minutes).
constexpr size_t kMaxGroups = 512;

struct Member {
  uint32_t plan = 0;
  std::vector<glm::vec4> positions, decoded;
  KeyFit fit;
};

struct Group {
  std::vector<uint32_t> members;  // indices into the member list
  std::vector<uint16_t> frames;
  uint64_t value_bits = 0;  // bits per key over every member
  bool alive = true;
  uint64_t cost() const { return frames.size() * (kKeyFrameBits + value_bits); }
};

struct Merge {
  int64_t saving = 0;  // bits; <= 0: not worth merging
  std::vector<uint16_t> frames;
};

}  // namespace

std::vector<bool> share_key_lists(std::vector<ChannelPlan>& plans, std::span<const ShareInput> inputs,
                                  uint32_t frames) {
  std::vector<Member> members;
  std::vector<Group> groups;
  std::map<std::vector<uint16_t>, uint32_t> group_of;  // identical lists start as one group
  for (uint32_t i = 0; i < plans.size(); ++i) {
    const ChannelPlan& p = plans[i];
    if (!inputs[i].share || p.kind != Kind::Animated || p.codes.size() != frames) continue;
    Member m;
    m.plan = i;
    m.positions = target_positions(inputs[i].metric.channel, inputs[i].target->data(), frames);
    m.decoded = decode_codes(p, inputs[i].metric.channel, frames);
    m.fit = KeyFit{inputs[i].metric, nullptr, nullptr, inputs[i].tolerance};
    const auto [it, added] = group_of.emplace(p.frames, static_cast<uint32_t>(groups.size()));
    if (added) {
      groups.emplace_back();
      groups.back().frames = p.frames;
    }
    Group& g = groups[it->second];
    g.members.push_back(static_cast<uint32_t>(members.size()));
    g.value_bits += p.widths.total();
    members.push_back(std::move(m));
  }
  for (Member& m : members) {
    m.fit.positions = m.positions.data();
    m.fit.decoded = m.decoded.data();
  }
  std::vector<bool> shared(plans.size(), false);
  const size_t count = groups.size();
  if (count < 2 || count > kMaxGroups) return shared;

  std::vector<KeyFit> fits;
  auto evaluate = [&](const Group& a, const Group& b) {
    Merge merge;
    const uint64_t separate = a.cost() + b.cost();
    const uint64_t per_key = kKeyFrameBits + a.value_bits + b.value_bits;
    // The shared list has at least as many keys as either list (each is its members' greedy
    // optimum); when even that would save nothing, skip the key removal.
    const uint64_t shortest = std::max(a.frames.size(), b.frames.size());
    if (shortest * per_key >= separate + static_cast<uint64_t>(kRunBits)) return merge;
    fits.clear();
    for (const uint32_t m : a.members) fits.push_back(members[m].fit);
    for (const uint32_t m : b.members) fits.push_back(members[m].fit);
    merge.frames = reduce_keys(fits, frames);
    merge.saving = static_cast<int64_t>(separate) - static_cast<int64_t>(merge.frames.size() * per_key) + kRunBits;
    return merge;
  };
  std::vector<Merge> pairs(count * count);  // [a * count + b], a < b
  for (size_t a = 0; a < count; ++a)
    for (size_t b = a + 1; b < count; ++b) pairs[a * count + b] = evaluate(groups[a], groups[b]);
  for (;;) {
    int64_t best = 0;
    size_t best_a = 0, best_b = 0;
    for (size_t a = 0; a < count; ++a) {
      if (!groups[a].alive) continue;
      for (size_t b = a + 1; b < count; ++b) {
        if (groups[b].alive && pairs[a * count + b].saving > best) {
          best = pairs[a * count + b].saving;
          best_a = a;
          best_b = b;
        }
      }
    }
    if (best <= 0) break;
    Group& into = groups[best_a];
    Group& from = groups[best_b];
    into.members.insert(into.members.end(), from.members.begin(), from.members.end());
    into.value_bits += from.value_bits;
    into.frames = std::move(pairs[best_a * count + best_b].frames);
    from.alive = false;
    from.members.clear();
    for (size_t c = 0; c < count; ++c) {
      if (c == best_a || !groups[c].alive) continue;
      const size_t lo = std::min(c, best_a), hi = std::max(c, best_a);
      pairs[lo * count + hi] = evaluate(groups[lo], groups[hi]);
    }
  }
  for (const Group& g : groups) {
    for (const uint32_t m : g.members) {
      plans[members[m].plan].frames = g.frames;
      shared[members[m].plan] = g.members.size() > 1;
    }
  }
  return shared;
}

}  // namespace ossa::cook::compress_detail
