// materials.cpp — see materials.h.
#include "viewer/materials.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <stb_image.h>

#include "runtime/internal/message.h"

namespace ossa::view {
namespace {

/// The largest texture the viewer decodes (the cooker embeds nothing larger): its size is read
/// from the header first, so a small file claiming 16384 x 16384 (3.5 GB of pixels after
/// decompression) costs nothing. External texture files are read up to kMaxTextureFileBytes.
constexpr int kMaxTextureSide = 16384;
constexpr uint64_t kMaxTexturePixels = uint64_t{64} << 20;
constexpr uint64_t kMaxTextureFileBytes = uint64_t{256} << 20;

/// Decodes an encoded image into an RGBA8 texture with mipmaps; 0 on failure (`why` says).
GLuint decode_texture(const uint8_t* bytes, size_t size, std::string& why) {
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
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  stbi_image_free(pixels);
  return t;
}

/// Reads a texture a file names by path: relative, inside the file's folder once `..` and symlinks
/// are resolved, a regular file (never a directory, FIFO or device: opened non-blocking and checked
/// again after opening), at most kMaxTextureFileBytes. A file from elsewhere cannot make the viewer
/// read outside its folder, hang on a FIFO or read /dev/zero until memory runs out.
bool read_texture_file(const std::string& asset_path, const std::string& named, std::vector<uint8_t>& bytes,
                       std::string& why) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path as_named(named);
  if (named.find('\0') != std::string::npos || as_named.is_absolute() || as_named.has_root_name()) {
    why = "a texture path must be relative to the file";
    return false;
  }
  const fs::path folder = fs::weakly_canonical(fs::absolute(fs::path(asset_path).parent_path(), ec), ec);
  const fs::path file = fs::weakly_canonical(fs::absolute(fs::path(asset_path).parent_path() / as_named, ec), ec);
  const fs::path rel = file.lexically_relative(folder);
  if (ec || rel.empty() || *rel.begin() == "..") {
    why = "it lies outside the file's folder";
    return false;
  }
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    why = "cannot open it";
    return false;
  }
  struct stat st{};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    why = "it is not a regular file";
    return false;
  }
  if (static_cast<uint64_t>(st.st_size) > kMaxTextureFileBytes) {
    ::close(fd);
    why = "it is over " + std::to_string(kMaxTextureFileBytes >> 20) + " MiB";
    return false;
  }
  bytes.resize(static_cast<size_t>(st.st_size));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  ::close(fd);
  bytes.resize(done);
  return true;
}

GLuint load_texture(const fb::Texture& texture, const std::string& asset_path, std::vector<std::string>& warnings) {
  std::string why;
  std::string what;
  GLuint t = 0;
  if (texture.data() != nullptr && texture.data()->size() > 0) {
    what = "embedded texture";
    t = decode_texture(texture.data()->data(), texture.data()->size(), why);
  } else if (texture.path() != nullptr && texture.path()->size() > 0) {
    const std::filesystem::path p = std::filesystem::path(asset_path).parent_path() / texture.path()->str();
    what = "texture " + detail::printable(p.string(), 400);
    std::vector<uint8_t> bytes;
    if (read_texture_file(asset_path, texture.path()->str(), bytes, why)) t = decode_texture(bytes.data(), bytes.size(), why);
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
  for (size_t i = 0; i < asset.material_count(); ++i) {
    const fb::Material& m = asset.material(i);
    GpuMaterial g;
    if (const fb::Vec3* d = m.diffuse()) g.diffuse = glm::vec3(d->x(), d->y(), d->z());
    g.opacity = m.opacity();
    if (m.textures() != nullptr) {
      for (const fb::Texture* t : *m.textures()) {
        GLuint* slot = t->role() == fb::TextureRole::Diffuse   ? &g.diffuse_map
                       : t->role() == fb::TextureRole::Normal  ? &g.normal_map
                       : t->role() == fb::TextureRole::Specular ? &g.specular_map
                                                                : nullptr;
        if (slot == nullptr || *slot != 0) continue;
        *slot = load_texture(*t, asset_path, warnings);
      }
    }
    // A material whose colour is black but which has a diffuse map means "the map is the colour".
    if (g.diffuse_map != 0 && g.diffuse == glm::vec3(0.0f)) g.diffuse = glm::vec3(1.0f);
    out.push_back(g);
  }
  if (out.empty()) out.push_back(GpuMaterial{});
  return out;
}

void destroy_materials(std::vector<GpuMaterial>& materials) {
  for (GpuMaterial& m : materials) {
    const GLuint textures[] = {m.diffuse_map, m.normal_map, m.specular_map};
    for (GLuint t : textures) {
      if (t != 0) glDeleteTextures(1, &t);
    }
  }
  materials.clear();
}

}  // namespace ossa::view
