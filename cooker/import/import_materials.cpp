// import_materials.cpp — Assimp materials -> Phong SourceMaterials with their textures, and the
// file's length unit.
//
// Materials map one to one onto aiMaterial, so a mesh's material index needs no remapping. The
// viewer shades Phong, so PBR files give their base colour as the diffuse colour. Textures end up
// as the encoded bytes the source has (embedded PNG/JPEG copied as is, external files read from
// disk next to the source), so a cooked file is self-contained; nothing is decoded or re-encoded
// here, which keeps the cooker's output byte-exact with the source images.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <assimp/scene.h>

#include "cooker/import/image_check.h"
#include "cooker/import/import_internal.h"
#include "cooker/model/input_log.h"

namespace ossa::cook::detail {
namespace {

constexpr float kDefaultShininess = 32.0f;
constexpr std::uintmax_t kMaxTextureBytes = 256u << 20;  // refuse absurd files rather than OOM

bool get_color(const aiMaterial& mat, const char* key, unsigned type, unsigned index, glm::vec3* out) {
  aiColor4D c;
  if (mat.Get(key, type, index, c) != AI_SUCCESS) return false;
  if (!std::isfinite(c.r) || !std::isfinite(c.g) || !std::isfinite(c.b)) return false;
  *out = glm::vec3(c.r, c.g, c.b);
  return true;
}

/// Forward slashes, no "./": paths from Windows-authored FBX files use backslashes.
std::string portable(std::string path) {
  for (char& c : path) c = c == '\\' ? '/' : c;
  while (path.rfind("./", 0) == 0) path.erase(0, 2);
  return path;
}

bool read_file(const std::filesystem::path& file, std::vector<uint8_t>* bytes, const std::string& reference) {
  // Recorded in the cook's input log (absent too); outside the read sandbox, refused by name.
  auto read = read_input(file, kMaxTextureBytes, reference);
  if (!read) return false;
  *bytes = std::move(*read);
  return true;
}

/// The texture file a material names: as written relative to the source, then just its file name
/// next to the source (authoring tools often store absolute paths from another machine).
bool read_external(const Context& ctx, const std::string& path, std::vector<uint8_t>* bytes, const std::string& label) {
  const std::string reference = label + "'s texture '" + path + "'";
  const std::filesystem::path dir = std::filesystem::path(ctx.path).parent_path();
  const std::filesystem::path as_written(path);
  if (as_written.is_relative() && read_file(dir / as_written, bytes, reference)) return true;
  return read_file(dir / as_written.filename(), bytes, reference);
}

bool ends_with_tga(std::string name) {
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name.size() >= 4 && name.compare(name.size() - 4, 4, ".tga") == 0;
}

/// Takes `bytes` as the texture's data: a PNG or JPEG as it is (identified by its bytes and fully
/// decoded, image_check.h); any other format stb_image reads (BMP, GIF, PSD, HDR, PIC, PNM, and
/// TGA where the name says .tga) converted to PNG with a warning, losslessly: the texture stage
/// (cooker/texture) then cooks every image from the same two encodings.
/// Anything else fails the input, named by `what` ("texture 'x.png'").
bool accept_image(const Context& ctx, std::vector<uint8_t> bytes, bool named_tga, const std::string& label,
                  const std::string& what, SourceTexture* out) {
  auto image = check_image(bytes);
  if (image) {
    out->mime = image->mime;
    out->data = std::move(bytes);
    return true;
  }
  if (const char* kind = other_image_format(bytes, named_tga)) {
    auto png = other_to_png(bytes, named_tga);
    if (!png) {
      ctx.fail(label + ": " + what + " " + png.error().message);
      return false;
    }
    ctx.warn(label + ": " + what + " is a " + kind + " image, embedded as PNG (same pixels)");
    out->mime = "image/png";
    out->data = std::move(*png);
    return true;
  }
  ctx.fail(label + ": " + what + " " + image.error().message);
  return false;
}

bool embedded(const Context& ctx, const aiTexture& tex, const std::string& label, SourceTexture* out) {
  if (tex.mHeight != 0 || !tex.pcData) {
    ctx.warn(label + ": embedded texture is raw texels, not PNG/JPEG, dropped");
    return false;
  }
  const auto* begin = reinterpret_cast<const uint8_t*>(tex.pcData);
  const std::string name = tex.mFilename.C_Str();
  const bool tga = ends_with_tga(name) || std::string(tex.achFormatHint) == "tga";
  out->name = name;
  // no path: an embedded image's name (glTF's "Image_0") is not a file
  return accept_image(ctx, std::vector<uint8_t>(begin, begin + tex.mWidth), tga, label,
                      "embedded texture '" + name + "'", out);
}

/// A path another machine wrote: absolute on POSIX ("/home/..."), a Windows drive ("C:/...", after
/// portable()) or a network share ("//server/...").
bool foreign_absolute(const std::string& path) {
  if (!path.empty() && path[0] == '/') return true;
  return path.size() >= 2 && std::isalpha(static_cast<unsigned char>(path[0])) && path[1] == ':';
}

/// The first texture of the first type in `types` the material has; false when none is usable.
bool find_texture(const Context& ctx, const aiMaterial& mat, std::initializer_list<aiTextureType> types,
                  TextureRole role, const std::string& label, SourceTexture* out) {
  aiString file;
  bool found = false;
  for (aiTextureType type : types) {
    if (mat.GetTextureCount(type) > 0 && mat.GetTexture(type, 0, &file) == AI_SUCCESS) {
      found = true;
      break;
    }
  }
  if (!found || file.length == 0) return false;
  out->role = role;
  if (const aiTexture* tex = ctx.scene->GetEmbeddedTexture(file.C_Str())) {
    const bool ok = embedded(ctx, *tex, label, out);
    if (out->name.empty()) out->name = file.C_Str();  // glTF's "*0": the image's index
    return ok;
  }
  std::string path = portable(file.C_Str());
  if (path.rfind('*', 0) == 0) {
    ctx.warn(label + ": names embedded texture " + path + " that the file does not have, dropped");
    return false;
  }
  if (foreign_absolute(path)) {
    // Never joined onto anything: the file is looked for by its name next to the source, and the
    // path kept is that name, so a viewer resolving it against the cooked file finds the same.
    const std::string name = std::filesystem::path(path).filename().string();
    ctx.warn(label + ": texture path '" + std::string(file.C_Str()) + "' is absolute, looked up as '" + name +
             "' next to the source");
    path = name;
  }
  out->path = path;
  out->name = path;
  std::vector<uint8_t> bytes;
  if (!read_external(ctx, path, &bytes, label)) {
    ctx.warn(label + ": texture '" + path + "' cannot be read, only its path is kept");
    return true;
  }
  return accept_image(ctx, std::move(bytes), ends_with_tga(path), label, "texture '" + path + "'", out);
}

/// The emissive colour and map, and a PBR source's factors and maps: occlusion (glTF's occlusion
/// texture arrives as Assimp's LIGHTMAP), metallic-roughness (glTF's one texture, G roughness and B
/// metallic, which Assimp reports as both METALNESS and DIFFUSE_ROUGHNESS). Separate metalness and
/// roughness images (other formats' PBR) have no cooked form: said in a warning, not dropped silently.
void import_pbr(const Context& ctx, const aiMaterial& mat, const std::string& label, SourceMaterial& out) {
  get_color(mat, AI_MATKEY_COLOR_EMISSIVE, &out.emissive);
  SourceTexture tex;
  if (find_texture(ctx, mat, {aiTextureType_EMISSIVE}, TextureRole::Emissive, label, &tex)) {
    out.textures.push_back(std::move(tex));
  }
  tex = {};
  if (find_texture(ctx, mat, {aiTextureType_AMBIENT_OCCLUSION, aiTextureType_LIGHTMAP}, TextureRole::Occlusion, label,
                   &tex)) {
    out.textures.push_back(std::move(tex));
  }
  float metallic = 1.0f, roughness = 1.0f;
  const bool has_metallic = mat.Get(AI_MATKEY_METALLIC_FACTOR, metallic) == AI_SUCCESS;
  const bool has_roughness = mat.Get(AI_MATKEY_ROUGHNESS_FACTOR, roughness) == AI_SUCCESS;
  if (has_metallic || has_roughness) {
    out.pbr = true;
    out.metallic = std::isfinite(metallic) ? std::clamp(metallic, 0.0f, 1.0f) : 1.0f;
    out.roughness = std::isfinite(roughness) ? std::clamp(roughness, 0.0f, 1.0f) : 1.0f;
  }
  aiString metalness, rough;
  const bool has_metalness_map = mat.GetTextureCount(aiTextureType_METALNESS) > 0 &&
                                 mat.GetTexture(aiTextureType_METALNESS, 0, &metalness) == AI_SUCCESS;
  const bool has_roughness_map = mat.GetTextureCount(aiTextureType_DIFFUSE_ROUGHNESS) > 0 &&
                                 mat.GetTexture(aiTextureType_DIFFUSE_ROUGHNESS, 0, &rough) == AI_SUCCESS;
  if (!has_metalness_map && !has_roughness_map) return;
  if (ctx.format != SourceFormat::Gltf || !has_metalness_map || !has_roughness_map ||
      std::string(metalness.C_Str()) != rough.C_Str()) {
    ctx.warn(label +
             ": separate metalness / roughness maps are not cooked (only glTF's combined metallic-roughness "
             "texture is)");
    return;
  }
  tex = {};
  if (find_texture(ctx, mat, {aiTextureType_METALNESS}, TextureRole::MetallicRoughness, label, &tex)) {
    out.textures.push_back(std::move(tex));
  }
}

SourceMaterial import_material(const Context& ctx, const aiMaterial& mat, unsigned index) {
  SourceMaterial out;
  aiString name;
  if (mat.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) out.name = name.C_Str();
  get_color(mat, AI_MATKEY_COLOR_AMBIENT, &out.ambient);
  if (!get_color(mat, AI_MATKEY_COLOR_DIFFUSE, &out.diffuse)) {
    get_color(mat, AI_MATKEY_BASE_COLOR, &out.diffuse);  // glTF without a Phong diffuse
  }
  get_color(mat, AI_MATKEY_COLOR_SPECULAR, &out.specular);
  float shininess = 0.0f;
  if (mat.Get(AI_MATKEY_SHININESS, shininess) == AI_SUCCESS && std::isfinite(shininess) && shininess > 0.0f) {
    out.shininess = shininess;
  } else {
    out.shininess = kDefaultShininess;
  }
  float opacity = 1.0f;
  if (mat.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && std::isfinite(opacity)) {
    out.opacity = std::clamp(opacity, 0.0f, 1.0f);
  }
  const std::string label = "material '" + out.name + "' (" + std::to_string(index) + ")";
  SourceTexture tex;
  if (find_texture(ctx, mat, {aiTextureType_DIFFUSE, aiTextureType_BASE_COLOR}, TextureRole::Diffuse, label, &tex)) {
    out.textures.push_back(std::move(tex));
  }
  tex = {};
  if (find_texture(ctx, mat, {aiTextureType_NORMALS, aiTextureType_NORMAL_CAMERA}, TextureRole::Normal, label, &tex)) {
    out.textures.push_back(std::move(tex));
  }
  tex = {};
  if (find_texture(ctx, mat, {aiTextureType_SPECULAR}, TextureRole::Specular, label, &tex)) {
    out.textures.push_back(std::move(tex));
  }
  import_pbr(ctx, mat, label, out);
  return out;
}

template <class T>
bool metadata_number(const aiMetadata* meta, const char* key, double* out) {
  T value{};
  if (!meta || !meta->Get(key, value)) return false;
  *out = static_cast<double>(value);
  return true;
}

}  // namespace

std::vector<SourceMaterial> import_materials(const Context& ctx) {
  std::vector<SourceMaterial> materials;
  for (unsigned i = 0; i < ctx.scene->mNumMaterials; ++i) {
    const aiMaterial* mat = ctx.scene->mMaterials[i];
    materials.push_back(mat ? import_material(ctx, *mat, i) : SourceMaterial{});
  }
  return materials;
}

float metres_per_unit(const Context& ctx) {
  switch (ctx.format) {
    case SourceFormat::Fbx: {
      // FBX states its unit as centimetres per unit; Assimp passes it through as metadata (and,
      // with AI_CONFIG_FBX_CONVERT_TO_M off, leaves the geometry in those units).
      double cm = 0.0;
      const aiMetadata* meta = ctx.scene->mMetaData;
      if ((metadata_number<float>(meta, "UnitScaleFactor", &cm) ||
           metadata_number<double>(meta, "UnitScaleFactor", &cm)) &&
          std::isfinite(cm) && cm > 0.0) {
        return static_cast<float>(cm / 100.0);
      }
      ctx.warn("FBX without a usable UnitScaleFactor: centimetres assumed");
      return 0.01f;
    }
    case SourceFormat::Collada:
      // Assimp 5.2 exposes <unit meter> only by scaling the scene root node by it, and model space
      // is Assimp's root space (that scale is folded into the root joint), so model space is
      // already metres: reporting the unit again would scale twice.
      return 1.0f;
    case SourceFormat::Bvh:
      // BVH has no unit field: 1 is a guess, said so in the warnings.
      ctx.warn("BVH states no length unit: 1 metre per unit assumed");
      return 1.0f;
    case SourceFormat::Gltf:  // glTF is metres by specification
    case SourceFormat::Other: return 1.0f;
  }
  return 1.0f;
}

}  // namespace ossa::cook::detail
