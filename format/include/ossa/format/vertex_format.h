// vertex_format.h — what each fb::VertexFormat means to a reader: byte size, component count,
// and the OpenGL type/normalization to hand glVertexAttribPointer.
//
// GL enums are spelled as numbers so that format/ does not depend on GL headers (the cooker has
// none). One table, used by the cooker to lay out vertices, by the loader to check layouts, and by
// the viewer to set attribute pointers.
#pragma once
#include <cstdint>

#include <ossa/format/ossa_generated.h>

namespace ossa {

struct VertexFormatInfo {
  uint8_t size;        // bytes
  uint8_t components;  // 1..4
  uint32_t gl_type;    // GL_FLOAT, GL_HALF_FLOAT, GL_UNSIGNED_SHORT, ...
  bool normalized;     // glVertexAttribPointer's normalized flag
  bool integer;        // use glVertexAttribIPointer (joint slots)
};

/// Facts about a format; size 0 for a value outside the enum (a corrupt file).
constexpr VertexFormatInfo vertex_format_info(fb::VertexFormat f) {
  constexpr uint32_t kFloat = 0x1406, kHalf = 0x140B, kUShort = 0x1403, kShort = 0x1402, kUByte = 0x1401;
  switch (f) {
    case fb::VertexFormat::Float32x2: return {8, 2, kFloat, false, false};
    case fb::VertexFormat::Float32x3: return {12, 3, kFloat, false, false};
    case fb::VertexFormat::Float32x4: return {16, 4, kFloat, false, false};
    case fb::VertexFormat::Unorm16x4: return {8, 4, kUShort, true, false};
    case fb::VertexFormat::Snorm16x2: return {4, 2, kShort, true, false};
    case fb::VertexFormat::Snorm16x4: return {8, 4, kShort, true, false};
    case fb::VertexFormat::Float16x2: return {4, 2, kHalf, false, false};
    case fb::VertexFormat::Uint8x4: return {4, 4, kUByte, false, true};
    case fb::VertexFormat::Uint16x4: return {8, 4, kUShort, false, true};
    case fb::VertexFormat::Unorm8x4: return {4, 4, kUByte, true, false};
  }
  return {0, 0, 0, false, false};
}

}  // namespace ossa
