// format_test.cpp — the shared encoders/decoders and hashes that both cooker and runtime rely on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>

namespace {

TEST(Hash, Fnv1aKnownVectors) {
  // Published FNV-1a 64 test vectors.
  EXPECT_EQ(ossa::hash_bytes("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(ossa::hash_bytes("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(ossa::hash_bytes("foobar", 6), 0x85944171f73967e8ull);
}

TEST(Hash, SkeletonHashSeparatesNamesAndParents) {
  const std::vector<std::string_view> ab_c{"ab", "c"}, a_bc{"a", "bc"};
  const std::vector<int16_t> p1{-1, 0}, p2{-1, -1};
  EXPECT_NE(ossa::skeleton_hash(ab_c, p1), ossa::skeleton_hash(a_bc, p1));
  EXPECT_NE(ossa::skeleton_hash(ab_c, p1), ossa::skeleton_hash(ab_c, p2));
  EXPECT_EQ(ossa::skeleton_hash(ab_c, p1), ossa::skeleton_hash(ab_c, p1));
}

TEST(Hash, SkeletonHashIsPinned) {
  // The value is stored in files (format v8): changing the function needs a format bump, and this
  // test is where that shows. Computed by this implementation when v8 was introduced.
  const std::vector<std::string_view> names{"Hips", "Spine", "LeftUpLeg_with_a_longer_name"};
  const std::vector<int16_t> parents{-1, 0, 0};
  EXPECT_EQ(ossa::skeleton_hash(names, parents), 0xd4abdc5a51f3b4f5ull);
  EXPECT_EQ(ossa::skeleton_hash({}, {}), ossa::skeleton_hash_finish(0, 0));
}

TEST(Hash, SkeletonHashSeesEveryByteLengthOrderAndParent) {
  // Every name length 1..40 (each tail shape and several whole words): flipping any one bit of
  // any byte, or growing the name by one byte, changes the hash; so do swapping two joints and
  // changing a parent. Also the incremental form the loader uses equals the span form.
  std::vector<uint64_t> seen;
  for (size_t len = 1; len <= 40; ++len) {
    std::string base(len, 'a');
    for (size_t i = 0; i < len; ++i) base[i] = static_cast<char>('a' + (i * 7) % 26);
    const std::vector<int16_t> parents{-1, 0};
    const auto h = [&](const std::string& name) {
      const std::vector<std::string_view> names{"root", name};
      const uint64_t whole = ossa::skeleton_hash(names, parents);
      const uint64_t parts = ossa::skeleton_hash_finish(
          ossa::skeleton_hash_joint(0, "root", -1) + ossa::skeleton_hash_joint(1, name, 0), 2);
      EXPECT_EQ(whole, parts);
      return whole;
    };
    const uint64_t h0 = h(base);
    seen.push_back(h0);
    for (size_t i = 0; i < len; ++i)
      for (int bit = 0; bit < 8; ++bit) {
        std::string changed = base;
        changed[i] = static_cast<char>(changed[i] ^ (1 << bit));
        ASSERT_NE(h(changed), h0) << "len " << len << " byte " << i << " bit " << bit;
      }
    EXPECT_NE(h(base + "a"), h0);
    const std::vector<std::string_view> ab{base, "root"}, ba{"root", base};
    const std::vector<int16_t> p{-1, -1}, q{-1, 0};
    EXPECT_NE(ossa::skeleton_hash(ab, p), ossa::skeleton_hash(ba, p));
    EXPECT_NE(ossa::skeleton_hash(ba, p), ossa::skeleton_hash(ba, q));
  }
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(std::adjacent_find(seen.begin(), seen.end()), seen.end()) << "two name lengths collided";
}

TEST(ClipCodec, BitWriterFieldsReadBackAndBitsPastTheValueAreZeros) {
  // Random fields of 1..57 bits (a key's widest) read back with read_bits where they were written,
  // LSB-first; a field wider than 64 bits writes the value's 64 and zeros after them.
  std::mt19937_64 rng(5);
  ossa::BitWriter writer;
  std::vector<std::pair<uint64_t, uint32_t>> fields;
  for (int i = 0; i < 2000; ++i) {
    const auto n = static_cast<uint32_t>(1 + rng() % 57);
    const uint64_t value = rng();
    fields.emplace_back(value & ((uint64_t{1} << n) - 1), n);
    writer.write(value, n);  // the bits above n are not written
  }
  writer.write(~uint64_t{0}, 70);
  writer.write(1, 1);
  const std::vector<uint8_t> bytes = writer.finish();
  uint64_t at = 0;
  for (const auto& [value, n] : fields) {
    ASSERT_EQ(ossa::read_bits(bytes.data(), at, n), value) << "field at bit " << at;
    at += n;
  }
  EXPECT_EQ(ossa::read_bits(bytes.data(), at, 32), 0xffffffffu);
  EXPECT_EQ(ossa::read_bits(bytes.data(), at + 32, 32), 0xffffffffu);
  EXPECT_EQ(ossa::read_bits(bytes.data(), at + 64, 6), 0u);
  EXPECT_EQ(ossa::read_bits(bytes.data(), at + 70, 1), 1u);
  EXPECT_EQ(writer.bit_size(), at + 71);
  EXPECT_EQ(bytes.size(), (at + 71 + 7) / 8 + ossa::kKeyValuePadding);
}

TEST(VertexCodec, OctahedralRoundTripWithinSnorm16Precision) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  float worst_deg = 0.0f;
  for (int i = 0; i < 100000; ++i) {
    ossa::Float3 n{g(rng), g(rng), g(rng)};
    const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    if (len < 1e-6f) continue;
    n = {n.x / len, n.y / len, n.z / len};
    const ossa::Float2 e = ossa::octahedral_encode(n);
    const ossa::Float2 q{ossa::snorm16_to_float(ossa::float_to_snorm16(e.x)),
                         ossa::snorm16_to_float(ossa::float_to_snorm16(e.y))};
    const ossa::Float3 d = ossa::octahedral_decode(q);
    // Angle via atan2(|n x d|, n.d) in double: acos of a float dot near 1 is itself off by ~0.02 deg.
    const double cx = double(n.y) * d.z - double(n.z) * d.y, cy = double(n.z) * d.x - double(n.x) * d.z,
                 cz = double(n.x) * d.y - double(n.y) * d.x;
    const double dot = double(n.x) * d.x + double(n.y) * d.y + double(n.z) * d.z;
    const double deg = std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * 57.29577951308232;
    worst_deg = std::fmax(worst_deg, static_cast<float>(deg));
  }
  EXPECT_LT(worst_deg, 0.01f);  // snorm16 octahedral: ~0.003 degrees expected
}

TEST(VertexCodec, OctahedralAxesExact) {
  const ossa::Float3 axes[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const ossa::Float3& a : axes) {
    const ossa::Float3 d = ossa::octahedral_decode(ossa::octahedral_encode(a));
    EXPECT_NEAR(d.x, a.x, 1e-6f);
    EXPECT_NEAR(d.y, a.y, 1e-6f);
    EXPECT_NEAR(d.z, a.z, 1e-6f);
  }
}

TEST(VertexCodec, HalfFloatExactAndRounded) {
  const float exact[] = {0.0f, -0.0f, 1.0f, -2.5f, 0.5f, 65504.0f, 6.103515625e-05f, 5.960464477539063e-08f};
  for (float f : exact) EXPECT_EQ(ossa::half_to_float(ossa::float_to_half(f)), f) << f;
  EXPECT_TRUE(std::isinf(ossa::half_to_float(ossa::float_to_half(1e6f))));
  EXPECT_TRUE(std::isnan(ossa::half_to_float(ossa::float_to_half(std::nanf("")))));
  // Every half value round-trips through float exactly.
  for (uint32_t h = 0; h < 0x10000; ++h) {
    const float f = ossa::half_to_float(static_cast<uint16_t>(h));
    if (std::isnan(f)) continue;
    EXPECT_EQ(ossa::float_to_half(f), h) << h;
  }
  // Round to nearest: UV error in [0, 1] stays under half an ulp at 1 (2^-12).
  for (int i = 0; i <= 1000; ++i) {
    const float f = static_cast<float>(i) / 1000.0f;
    EXPECT_LE(std::fabs(ossa::half_to_float(ossa::float_to_half(f)) - f), 1.0f / 4096.0f);
  }
}

TEST(VertexCodec, UnormSnormEndpoints) {
  EXPECT_EQ(ossa::float_to_unorm16(0.0f), 0);
  EXPECT_EQ(ossa::float_to_unorm16(1.0f), 65535);
  EXPECT_EQ(ossa::float_to_unorm16(2.0f), 65535);
  EXPECT_EQ(ossa::float_to_snorm16(-1.0f), -32767);
  EXPECT_FLOAT_EQ(ossa::snorm16_to_float(-32768), -1.0f);
  EXPECT_FLOAT_EQ(ossa::unorm16_to_float(65535), 1.0f);
}

TEST(VertexFormat, SizesMatchComponentTypes) {
  using F = ossa::fb::VertexFormat;
  EXPECT_EQ(ossa::vertex_format_info(F::Float32x3).size, 12);
  EXPECT_EQ(ossa::vertex_format_info(F::Unorm16x4).size, 8);
  EXPECT_EQ(ossa::vertex_format_info(F::Snorm16x2).size, 4);
  EXPECT_EQ(ossa::vertex_format_info(F::Float16x2).size, 4);
  EXPECT_EQ(ossa::vertex_format_info(F::Uint8x4).size, 4);
  EXPECT_TRUE(ossa::vertex_format_info(F::Uint16x4).integer);
  EXPECT_TRUE(ossa::vertex_format_info(F::Unorm8x4).normalized);
  EXPECT_EQ(ossa::vertex_format_info(static_cast<F>(200)).size, 0);
}

}  // namespace
