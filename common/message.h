// message.h — turning untrusted file text into safe, readable message text (internal to runtime/
// and its tools; not part of the public API).
//
// Error messages quote joint, mesh and clip names straight from a file that has not been trusted
// yet, and ossa-inspect prints them to a terminal. A crafted name could carry escape sequences,
// invalid UTF-8 or megabytes of text, so every quoted name goes through printable(): valid UTF-8
// passes unchanged (joint names in Japanese are legitimate), control bytes and invalid sequences
// become \xNN, and long text is cut. Header-only because it is three small functions.
//
// Cost: printable() is O(min(text size, max_chars)); format() is one vsnprintf plus one allocation.
#pragma once
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

// printf-style checking. MinGW-w64's C++ runtime uses its C99-conforming printf (libstdc++ turns on
// __USE_MINGW_ANSI_STDIO), whose %zu and %llu GCC checks as gnu_printf; plain `printf` there means
// the Microsoft CRT's dialect. MSVC has no such attribute.
#if defined(__MINGW32__)
#define OSSA_PRINTF_FORMAT(fmt, args) __attribute__((format(gnu_printf, fmt, args)))
#elif defined(__GNUC__) || defined(__clang__)
#define OSSA_PRINTF_FORMAT(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define OSSA_PRINTF_FORMAT(fmt, args)
#endif

namespace ossa::detail {

/// Length of the valid UTF-8 sequence starting at s[i] (2..4), or 0 when it is not one. Overlong
/// forms, surrogates and code points past U+10FFFF count as invalid, as RFC 3629 says.
inline size_t utf8_sequence_length(std::string_view s, size_t i) {
  const auto b = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;
    if (c == 0xED) hi = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (s.size() - i < n) return 0;
  if (b(i + 1) < lo || b(i + 1) > hi) return 0;
  for (size_t k = 2; k < n; ++k)
    if (b(i + k) < 0x80 || b(i + k) > 0xBF) return 0;
  return n;
}

/// Text safe to print: valid UTF-8 kept, control bytes and invalid bytes as \xNN, a backslash
/// doubled, cut after about max_chars bytes with "...".
inline std::string printable(std::string_view text, size_t max_chars = 80) {
  std::string out;
  out.reserve(text.size() < max_chars ? text.size() : max_chars);
  for (size_t i = 0; i < text.size();) {
    if (out.size() >= max_chars) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      if (c == '\\') out += '\\';
      out += static_cast<char>(c);
      ++i;
    } else if (const size_t n = c >= 0x80 ? utf8_sequence_length(text, i) : 0; n != 0) {
      out.append(text.substr(i, n));
      i += n;
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
      ++i;
    }
  }
  return out;
}

/// printf into a std::string.
#if defined(__GNUC__)
OSSA_PRINTF_FORMAT(1, 2)
#endif
inline std::string format(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::string out;
  if (n > 0) {
    out.resize(static_cast<size_t>(n) + 1);
    std::vsnprintf(out.data(), out.size(), fmt, args);
    out.resize(static_cast<size_t>(n));
  }
  va_end(args);
  return out;
}

}  // namespace ossa::detail
