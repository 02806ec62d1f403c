// materials.cpp — see materials.h.
#include "viewer/materials.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include <stb_image.h>

#include <ossa/loader/texture.h>
#include "common/message.h"
#include "common/open_beneath.h"

namespace ossa::view {
namespace {

/// The largest texture the viewer decodes (the cooker embeds nothing larger): its size is read
/// from the header first, so a small file claiming 16384 x 16384 (3.5 GB of pixels after
/// decompression) costs nothing. External texture files are read up to kMaxTextureFileBytes.
constexpr int kMaxTextureSide = 16384;
constexpr uint64_t kMaxTexturePixels = uint64_t{64} << 20;
constexpr uint64_t kMaxTextureFileBytes = uint64_t{256} << 20;

/// Decodes an encoded image (a texture cooked with --texture-format source, or one referenced by
/// path) into an RGBA8 texture (sRGB for colour) with mipmaps; 0 on failure (`why` says).
GLuint decode_texture(const uint8_t* bytes, size_t size, bool srgb, uint64_t& gpu_bytes, std::string& why) {
  if (size > static_cast<size_t>(INT_MAX)) {
    why = "image too large";
    return 0;
  }
  int w = 0, h = 0, channels = 0;
  if (!stbi_info_from_memory(bytes, static_cast<int>(size), &w, &h, &channels)) {
    why = stbi_failure_reason() ? stbi_failure_reason() : "not an image it can read";
    return 0;
  }
  if (w <= 0 || h <= 0 || w > kMaxTextureSide || h > kMaxTextureSide ||
      static_cast<uint64_t>(w) * static_cast<uint64_t>(h) > kMaxTexturePixels) {
    why = "it claims " + std::to_string(w) + " x " + std::to_string(h) + " pixels, over the viewer's limit of " +
          std::to_string(kMaxTextureSide) + " per side and " + std::to_string(kMaxTexturePixels) + " pixels";
    return 0;
  }
  // Assimp (and so the cooker) keeps texture coordinates with v = 0 at the bottom, as GL does;
  // images start with their top row, so flip them on load.
  stbi_set_flip_vertically_on_load(1);
  stbi_uc* pixels = stbi_load_from_memory(bytes, static_cast<int>(size), &w, &h, &channels, 4);
  if (pixels == nullptr) {
    why = stbi_failure_reason() ? stbi_failure_reason() : "cannot decode";
    return 0;
  }
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
  glGenerateMipmap(GL_TEXTURE_2D);
  gpu_bytes += texture_chain_bytes(fb::TextureEncoding::Rgba8, static_cast<uint32_t>(w), static_cast<uint32_t>(h),
                                   texture_full_mip_count(static_cast<uint32_t>(w), static_cast<uint32_t>(h)));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  stbi_image_free(pixels);
  return t;
}

/// The GL internal format of a cooked encoding, or 0 where this context cannot sample it (S3TC is
/// an extension, though every desktop driver has it; RGTC is core since GL 3.0).
GLenum gl_format(fb::TextureEncoding encoding, bool srgb) {
  static const bool s3tc = epoxy_has_gl_extension("GL_EXT_texture_compression_s3tc");
  static const bool s3tc_srgb = s3tc && (epoxy_has_gl_extension("GL_EXT_texture_sRGB") ||
                                         epoxy_has_gl_extension("GL_EXT_texture_compression_s3tc_srgb"));
  switch (encoding) {
    case fb::TextureEncoding::Rgba8: return srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8;
    case fb::TextureEncoding::Bc1:
      if (srgb) return s3tc_srgb ? GL_COMPRESSED_SRGB_S3TC_DXT1_EXT : 0;
      return s3tc ? GL_COMPRESSED_RGB_S3TC_DXT1_EXT : 0;
    case fb::TextureEncoding::Bc3:
      if (srgb) return s3tc_srgb ? GL_COMPRESSED_SRGB_ALPHA_S3TC_DXT5_EXT : 0;
      return s3tc ? GL_COMPRESSED_RGBA_S3TC_DXT5_EXT : 0;
    case fb::TextureEncoding::Bc4: return GL_COMPRESSED_RED_RGTC1;
    case fb::TextureEncoding::Bc5: return GL_COMPRESSED_RG_RGTC2;
    default: return 0;
  }
}

/// Uploads a cooked mip chain level by level straight from the file's bytes: no decode, no
/// mipmap generation. A BC4 (grey) map is swizzled to R, R, R so the shader reads it like any
/// other; a BC5 normal map gives x and y, and the shader rebuilds z. 0 on failure (`why` says).
GLuint upload_cooked(const TextureView& view, uint64_t& gpu_bytes, std::string& why) {
  const GLenum format = gl_format(view.encoding(), view.srgb());
  if (format == 0) {
    why = std::string("this OpenGL driver cannot sample ") + fb::EnumNameTextureEncoding(view.encoding()) +
          (view.srgb() ? " sRGB" : "") + " textures (no GL_EXT_texture_compression_s3tc)";
    return 0;
  }
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, static_cast<GLint>(view.mip_count()) - 1);
  for (uint32_t k = 0; k < view.mip_count(); ++k) {
    const TextureLevel level = view.level(k);
    const auto w = static_cast<GLsizei>(level.width), h = static_cast<GLsizei>(level.height);
    if (view.encoding() == fb::TextureEncoding::Rgba8) {
      glTexImage2D(GL_TEXTURE_2D, static_cast<GLint>(k), static_cast<GLint>(format), w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                   level.bytes.data());
    } else {
      glCompressedTexImage2D(GL_TEXTURE_2D, static_cast<GLint>(k), format, w, h, 0,
                             static_cast<GLsizei>(level.bytes.size()), level.bytes.data());
    }
    gpu_bytes += level.bytes.size();
  }
  if (view.encoding() == fb::TextureEncoding::Bc4) {
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_G, GL_RED);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_B, GL_RED);
  }
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  if (glGetError() != GL_NO_ERROR) {
    glDeleteTextures(1, &t);
    why = "the driver refused its mip levels";
    return 0;
  }
  return t;
}

/// Reads a texture a file names by path: relative, beneath the file's folder, a regular file with
/// no other hard links (never a directory, FIFO or device), at most kMaxTextureFileBytes. Resolved
/// and opened in one step from the folder's descriptor and checked on the opened file, through the
/// cooker's door (common/open_beneath.h): a file from elsewhere cannot make the viewer read
/// outside its folder, even by swapping a symlink in while it loads, hang on a FIFO or read
/// /dev/zero until memory runs out.
bool read_texture_file(const std::string& asset_path, const std::string& named, std::vector<uint8_t>& bytes,
                       std::string& why) {
  namespace fs = std::filesystem;
  const fs::path as_named(named);
  if (named.find('\0') != std::string::npos || as_named.is_absolute() || as_named.has_root_name()) {
    why = "a texture path must be relative to the file";
    return false;
  }
  const fs::path folder = fs::path(asset_path).parent_path();
  const cook::ReadRoots roots({folder.empty() ? fs::path(".") : folder});
  const cook::OpenedFile f =
      cook::open_beneath(&roots, (folder.empty() ? fs::path(".") : folder) / as_named, true, false);
  switch (f.outcome) {
    case cook::OpenOutcome::kOpened: break;
    case cook::OpenOutcome::kOutside: why = "it lies outside the file's folder"; return false;
    case cook::OpenOutcome::kNotRegular:
      why = std::string("it is not a regular file (") + cook::file_kind(f.st) + ")";
      return false;
    case cook::OpenOutcome::kHardLinked:
      why = "it has " + std::to_string(f.st.st_nlink) + " hard links (another name for it may lie outside the folder)";
      return false;
    case cook::OpenOutcome::kAbsent:
    case cook::OpenOutcome::kError: why = std::string("cannot open it: ") + std::strerror(f.error); return false;
  }
  if (static_cast<uint64_t>(f.st.st_size) > kMaxTextureFileBytes) {
    ::close(f.fd);
    why = "it is over " + std::to_string(kMaxTextureFileBytes >> 20) + " MiB";
    return false;
  }
  bytes.resize(static_cast<size_t>(f.st.st_size));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(f.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  ::close(f.fd);
  bytes.resize(done);
  return true;
}

GLuint load_texture(const fb::Texture& texture, const std::string& asset_path, uint64_t& gpu_bytes,
                    std::vector<std::string>& warnings) {
  std::string why;
  std::string what;
  GLuint t = 0;
  const TextureView view{&texture};
  // Colour maps are sRGB: sampled through an sRGB format, they come back linear for lighting.
  const bool colour = texture.role() == fb::TextureRole::Diffuse || texture.role() == fb::TextureRole::Emissive;
  if (view.gpu_ready()) {
    what = "embedded texture";
    t = upload_cooked(view, gpu_bytes, why);
  } else if (texture.data() != nullptr && texture.data()->size() > 0) {
    what = "embedded texture";
    t = decode_texture(texture.data()->data(), texture.data()->size(), colour, gpu_bytes, why);
  } else if (texture.path() != nullptr && texture.path()->size() > 0) {
    const std::filesystem::path p = std::filesystem::path(asset_path).parent_path() / texture.path()->str();
    what = "texture " + detail::printable(p.string(), 400);
    std::vector<uint8_t> bytes;
    if (read_texture_file(asset_path, texture.path()->str(), bytes, why))
      t = decode_texture(bytes.data(), bytes.size(), colour, gpu_bytes, why);
  } else {
    return 0;
  }
  if (t == 0) warnings.push_back(asset_path + ": " + what + " left out: " + why);
  return t;
}

}  // namespace

std::vector<GpuMaterial> create_materials(const Asset& asset, const std::string& asset_path,
                                          std::vector<std::string>& warnings) {
  std::vector<GpuMaterial> out;
  std::map<const fb::Texture*, GLuint> shared;
  std::vector<std::string> pbr_only;  // materials whose metallic-roughness the Phong shader does not use
  for (size_t i = 0; i < asset.material_count(); ++i) {
    const fb::Material& m = asset.material(i);
    GpuMaterial g;
    if (const fb::Vec3* d = m.diffuse()) g.diffuse = glm::vec3(d->x(), d->y(), d->z());
    if (const fb::Vec3* e = m.emissive()) g.emissive = glm::vec3(e->x(), e->y(), e->z());
    g.opacity = m.opacity();
    bool metallic_roughness_map = false;
    if (m.textures() != nullptr) {
      for (const fb::Texture* t : *m.textures()) {
        metallic_roughness_map |= t->role() == fb::TextureRole::MetallicRoughness;
        GLuint* slot = t->role() == fb::TextureRole::Diffuse     ? &g.diffuse_map
                       : t->role() == fb::TextureRole::Normal    ? &g.normal_map
                       : t->role() == fb::TextureRole::Specular  ? &g.specular_map
                       : t->role() == fb::TextureRole::Occlusion ? &g.occlusion_map
                       : t->role() == fb::TextureRole::Emissive  ? &g.emissive_map
                                                                 : nullptr;
        if (slot == nullptr || *slot != 0) continue;
        // Materials sharing a texture table share its GL texture (format v7 writes one table per
        // distinct image and role).
        if (const auto it = shared.find(t); it != shared.end()) {
          *slot = it->second;
          continue;
        }
        *slot = load_texture(*t, asset_path, g.texture_bytes, warnings);
        if (*slot != 0) shared.emplace(t, *slot);
      }
    }
    // A material whose colour is black but which has a diffuse map means "the map is the colour".
    if (g.diffuse_map != 0 && g.diffuse == glm::vec3(0.0f)) g.diffuse = glm::vec3(1.0f);
    if (metallic_roughness_map || (m.pbr() != nullptr && m.pbr()->metallic() > 0.0f))
      pbr_only.push_back("'" + detail::printable(flatbuffers::GetString(m.name()), 80) + "'");
    out.push_back(g);
  }
  if (!pbr_only.empty()) {
    std::string names;
    for (size_t i = 0; i < pbr_only.size() && i < 4; ++i) names += (i ? ", " : "") + pbr_only[i];
    if (pbr_only.size() > 4) names += " and " + std::to_string(pbr_only.size() - 4) + " more";
    warnings.push_back(
        asset_path + ": metallic-roughness of material" + (pbr_only.size() > 1 ? "s " : " ") + names +
        " not shown (the viewer shades Phong: base colour, normal, occlusion and emissive maps are used)");
  }
  if (out.empty()) out.push_back(GpuMaterial{});
  return out;
}

void destroy_materials(std::vector<GpuMaterial>& materials) {
  std::set<GLuint> deleted;  // shared textures are deleted once
  for (GpuMaterial& m : materials) {
    const GLuint textures[] = {m.diffuse_map, m.normal_map, m.specular_map, m.occlusion_map, m.emissive_map};
    for (GLuint t : textures) {
      if (t != 0 && deleted.insert(t).second) glDeleteTextures(1, &t);
    }
  }
  materials.clear();
}

uint64_t texture_bytes(const std::vector<GpuMaterial>& materials) {
  uint64_t total = 0;
  for (const GpuMaterial& m : materials) total += m.texture_bytes;
  return total;
}

}  // namespace ossa::view
