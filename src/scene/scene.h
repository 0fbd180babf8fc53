// Scene: the plain data every importer produces and every later stage reads (as const Scene&).
//
// Indices, not pointers; no tinygltf, Embree or OIIO types. Geometry is stored per mesh in object
// space; instances place meshes in the world with a double-precision world_from_object transform.
// A glTF mesh with several primitives becomes several Meshes (one material each) and a node that
// uses it becomes one Instance per primitive.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/vecmath.h"
#include "scene/environment.h"
#include "scene/padded_vector.h"

namespace whitted {

// ---------------------------------------------------------------------------------------------
// Geometry

/// Triangle mesh in object space, one material. Optional attributes are empty when absent.
struct Mesh {
    std::string name;                 ///< "<gltf mesh name>/<primitive index>" or a user name
    PaddedVector<Vec3f> positions;    ///< object-space vertex positions; 16 zero bytes follow the last
                                      ///< one in the allocation (the Embree backend shares the array)
    std::vector<Vec3f> normals;       ///< per-vertex shading normals (unit), same count as positions
    std::vector<Vec4f> tangents;      ///< xyz unit tangent, w = bitangent sign (+1/-1); may be empty
    std::vector<Vec2f> uv0;           ///< TEXCOORD_0; may be empty
    std::vector<Vec2f> uv1;           ///< TEXCOORD_1; may be empty
    std::vector<Vec4f> colors;        ///< COLOR_0 as linear RGBA; may be empty
    std::vector<uint32_t> indices;    ///< 3 per triangle, counter-clockwise front faces
    uint32_t material = 0;            ///< index into Scene::materials
    bool deforming = false;           ///< an animation moves its vertices (skin, morph weights): between
                                      ///< frames they are rewritten in place, and accelerators keep the
                                      ///< mesh apart, built to be refit (scene_update.h)

    size_t triangle_count() const { return indices.size() / 3; }
    /// Object-space bounds of the positions (computed, not cached).
    Bounds3d bounds() const {
        Bounds3d b;
        for (const Vec3f& p : positions) b.extend(Vec3d(p));
        return b;
    }
};

/// A mesh placed in the world.
struct Instance {
    uint32_t mesh = 0;                ///< index into Scene::meshes
    Mat4d world_from_object;          ///< composed in double precision from the node hierarchy
    std::string node_name;            ///< the glTF node (or scene-file entry) it came from
    int32_t node = -1;                ///< glTF node index, -1 when not from a glTF node
    bool moving = false;              ///< an animation changes world_from_object: accelerators keep it
                                      ///< out of the flattened static geometry (scene_update.h)
};

/// Analytic sphere (scene files), intersected by its quadratic in every backend. Shading UVs:
/// u = (atan2(d.x, d.z) / 2pi) + 0.5 (longitude about +Y), v = acos(d.y) / pi (0 at the +Y pole),
/// with d the unit vector from the centre to the point.
struct Sphere {
    Vec3d center;                     ///< world-space centre
    double radius = 1.0;              ///< world-space radius (> 0)
    uint32_t material = 0;            ///< index into Scene::materials
    std::string name;
};

/// Which analytic quadric a Quadric is.
enum class QuadricKind : uint8_t { Cylinder, Cone, Disc };

/// Analytic quadric (scene files): a cylinder, a cone (truncated: a radius at each end, as NFF
/// writes them) or a disc, defined in its own object space about the +Z axis and placed by
/// world_from_object (any invertible affine map: a non-uniform scale makes an elliptic cylinder).
/// Object space:
///   - cylinder and cone: the side x^2 + y^2 = R(z)^2, R(z) = radius0 + (radius1 - radius0) z / height,
///     0 <= z <= height; with `caps`, closed by discs at z = 0 (radius0) and z = height (radius1)
///     into a solid (then a ray crosses it at most twice, in and out, with no gap at the rims);
///   - disc: z = 0, inner_radius <= sqrt(x^2 + y^2) <= radius0 (an annulus when inner_radius > 0),
///     front side +Z.
/// Normals face outward (caps: -Z at the base, +Z at the top). Shading UVs: on the side
/// u = atan2(y, x) / 2pi + 0.5 (about +Z), v = z / height; on caps and discs u = 0.5 + x / 2r,
/// v = 0.5 + y / 2r with r the cap's radius. Intersected in double in object space by every
/// backend (accel/common/quadric.h).
struct Quadric {
    QuadricKind kind = QuadricKind::Cylinder;
    double radius0 = 1.0;             ///< radius at z = 0 (> 0 for discs; >= 0 for cones)
    double radius1 = 1.0;             ///< radius at z = height (= radius0 for cylinders; unused by discs)
    double height = 1.0;              ///< length along +Z (> 0; unused by discs)
    double inner_radius = 0.0;        ///< discs: the hole's radius (0 <= inner < radius0)
    bool caps = false;                ///< cylinders and cones: closed at both ends
    Mat4d world_from_object;
    Mat4d object_from_world;          ///< its inverse (the importer computes it)
    uint32_t material = 0;            ///< index into Scene::materials
    std::string name;
};

/// A quadric placed by its ends: +Z from `base` towards `apex` (height |apex - base| > 0), X and Y
/// any perpendicular pair, then `transform`. Cylinders take radius0 for both ends. For a disc,
/// `base` is the centre and `apex - base` the normal (its length does not matter).
Quadric make_quadric(QuadricKind kind, const Vec3d& base, const Vec3d& apex, double radius0, double radius1,
                     bool caps, const Mat4d& transform = Mat4d::identity());

/// Exact world-space box of a quadric: the box of its end circles (a cone is their convex hull),
/// each circle's half-extent along axis k being r sqrt(M(k,0)^2 + M(k,1)^2) for M =
/// world_from_object. Computed in double.
Bounds3d quadric_bounds(const Quadric& q);

/// A point of a quadric's surface (QuadricPoint::part: 0 the side or a disc, 1 the base cap,
/// 2 the top cap).
struct QuadricPoint {
    Vec3d p;                          ///< world space, on the surface
    Vec3d n;                          ///< unit outward world normal (discs: the +Z side)
    double u = 0, v = 0;              ///< shading UVs (Quadric)
    double uv_area = 1;               ///< world area of one UV unit square about the point (> 0)
    int part = 0;
};

/// The surface point of `q` nearest a world point near it (a hit point o + t d carries the error
/// of t): the object-space point is moved onto `face` (QuadricPoint::part: the face the ray
/// crossed, Hit::prim) or, for face < 0, onto the side or cap it lies closest to, in double.
/// `uvs` false leaves u, v and uv_area at their defaults (a material that reads no texture).
QuadricPoint quadric_point(const Quadric& q, const Vec3d& world, int face = -1, bool uvs = true);

/// Infinite plane (scene files): the points p with dot(normal, p - point) = 0. It has no finite
/// bounds, so it is kept out of every acceleration structure and tested on its own beside them.
/// Its front side faces `normal`. Shading UVs are world units along `u_axis` and
/// cross(normal, u_axis) measured from `point`.
struct Plane {
    Vec3d point;                      ///< a world-space point on the plane
    Vec3d normal{0, 1, 0};            ///< unit normal (front side)
    Vec3d u_axis{1, 0, 0};            ///< unit tangent, perpendicular to normal (UV u direction)
    uint32_t material = 0;            ///< index into Scene::materials
    std::string name;
};

/// Which kind of geometry a geometry id names. Ids are dense: meshes [0, M), spheres
/// [M, M + S), quadrics [M + S, M + S + Q), planes after them (Hit::geom, SurfaceFilter::mesh_flags).
enum class GeomKind : uint8_t { Mesh, Sphere, Quadric, Plane };

// ---------------------------------------------------------------------------------------------
// Textures

enum class WrapMode : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
enum class FilterMode : uint8_t { Nearest, Linear };

/// One MIP level: 8-bit RGBA texels, row-major, top row first (glTF UV (0,0) = top-left).
struct MipLevel {
    int width = 0, height = 0;
    std::vector<uint8_t> texels;      ///< width * height * 4 bytes
};

/// What a texture is: decoded texels, or a procedural pattern evaluated per lookup.
enum class TextureKind : uint8_t { Image, Checker };

/// Procedural checkerboard (Whitted 1980's floor). Squares of side `size` (UV or world units)
/// alternate between `color_a` (the square at the origin's positive corner) and `color_b`.
/// In UV space the parity is floor(u/size) + floor(v/size); in world space it is the 3D solid
/// checker floor(x/size) + floor(y/size) + floor(z/size), evaluated a tiny step inside the
/// surface so points on an axis-aligned face never flicker between two cells.
struct Checker {
    Color color_a{1.f};               ///< linear RGB
    Color color_b{0.f};               ///< linear RGB
    float size = 1.f;                 ///< side of one square (> 0)
    bool world_space = false;         ///< false: UV set of the TextureRef; true: world position
};

/// A decoded texture. Texels stay 8-bit to keep memory in check (a 2k RGBA level is 16 MB);
/// `srgb` says whether the lookup converts them from the sRGB transfer to linear, so every value
/// a lookup returns is linear. levels[0] is full resolution; each next level halves (box filter
/// in linear space).
struct Texture {
    std::string name;                 ///< image name or URI, for messages
    TextureKind kind = TextureKind::Image;
    Checker checker;                  ///< TextureKind::Checker only
    std::vector<MipLevel> levels;
    bool srgb = false;                ///< true for color data (baseColor, emissive)
    WrapMode wrap_s = WrapMode::Repeat;
    WrapMode wrap_t = WrapMode::Repeat;
    FilterMode mag_filter = FilterMode::Linear;
    FilterMode min_filter = FilterMode::Linear;
    bool use_mips = true;             ///< false when the sampler's minFilter has no mipmap
    int32_t image = -1;               ///< glTF image index it was decoded from (-1 = procedural)
};

/// KHR_texture_transform: uv' = T * R * S * uv.
struct TextureTransform {
    Vec2f offset{0.f, 0.f};
    float rotation = 0.f;             ///< radians, counter-clockwise in UV space
    Vec2f scale{1.f, 1.f};
    bool identity() const { return offset == Vec2f{0, 0} && rotation == 0.f && scale == Vec2f{1, 1}; }
};

/// A material's reference to a texture.
struct TextureRef {
    int32_t texture = -1;             ///< index into Scene::textures, -1 = none
    uint32_t uv_set = 0;              ///< 0 = TEXCOORD_0, 1 = TEXCOORD_1
    float scale = 1.f;                ///< normalTexture.scale or occlusionTexture.strength
    TextureTransform transform;
    bool valid() const { return texture >= 0; }
};

// ---------------------------------------------------------------------------------------------
// Materials

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

/// Whitted's (1980) surface coefficients at one point, all linear RGB.
/// I = Ia*Ka + sum_i Is_i*fat_i*s_i*(kd (N.L) + ks (N.H)^n) + kr*R + kt*T + emission
struct WhittedCoeffs {
    Color kd{0.f};                    ///< diffuse reflectance
    Color ka{0.f};                    ///< ambient reflectance (multiplies the ambient light Ia)
    Color ks{0.f};                    ///< specular highlight coefficient (Phong-Blinn)
    float n = 1.f;                    ///< highlight exponent
    Color kr{0.f};                    ///< mirror reflection weight (Whitted's (1980) Ks on R)
    Color kt{0.f};                    ///< transmission weight (Whitted's (1980) Kt on T)
    Color kg{0.f};                    ///< glossy reflection weight: the environment prefiltered by `roughness`
                                      ///< about R (the extension for surfaces too rough for kr; 0 for classic materials)
    float roughness = 0.f;            ///< GGX roughness of the glossy reflection, [0, 1]
    float ior = 1.5f;                 ///< index of refraction of the inside medium
    bool thin = true;                 ///< thin-walled: transmitted rays go straight through
    Color emission{0.f};              ///< emitted radiance added as is
    Color absorption{0.f};            ///< Beer-Lambert coefficient per unit length inside (volume)
};

/// Which model a material uses: glTF metallic-roughness (mapped per hit point by
/// shading/material_mapping) or Whitted's (1980) coefficients given directly (scene files).
enum class MaterialModel : uint8_t { GltfPbr, Classic };

struct Material {
    std::string name;
    MaterialModel model = MaterialModel::GltfPbr;

    // glTF 2.0 core (defaults from the specification)
    Vec4f base_color{1.f, 1.f, 1.f, 1.f};      ///< linear RGBA factor
    TextureRef base_color_texture;
    float metallic = 1.f;
    float roughness = 1.f;
    TextureRef metallic_roughness_texture;     ///< B = metallic, G = roughness
    TextureRef normal_texture;                 ///< scale = normalTexture.scale
    TextureRef occlusion_texture;              ///< R channel; scale = strength
    Color emissive{0.f};                       ///< emissiveFactor
    TextureRef emissive_texture;
    float emissive_strength = 1.f;             ///< KHR_materials_emissive_strength
    AlphaMode alpha_mode = AlphaMode::Opaque;
    float alpha_cutoff = 0.5f;
    bool double_sided = false;
    bool unlit = false;                        ///< KHR_materials_unlit

    // KHR_materials_transmission / ior / volume / specular
    float transmission = 0.f;
    TextureRef transmission_texture;           ///< R channel
    float ior = 1.5f;
    bool has_volume = false;                   ///< KHR_materials_volume present with thickness > 0
    float thickness = 0.f;
    Color attenuation_color{1.f};
    float attenuation_distance = kInfinity;
    float specular = 1.f;                      ///< KHR_materials_specular specularFactor
    Color specular_color{1.f};                 ///< specularColorFactor
    TextureRef specular_texture;               ///< A channel
    TextureRef specular_color_texture;         ///< RGB, sRGB-encoded

    // The layered extensions (docs/materials.md, "Layers"). Defaults switch each layer off.
    // KHR_materials_clearcoat: a dielectric coat (ior 1.5) over everything below.
    float clearcoat = 0.f;                     ///< clearcoatFactor
    TextureRef clearcoat_texture;              ///< R channel
    float clearcoat_roughness = 0.f;           ///< clearcoatRoughnessFactor
    TextureRef clearcoat_roughness_texture;    ///< G channel
    TextureRef clearcoat_normal_texture;       ///< scale = clearcoatNormalTexture.scale
    // KHR_materials_sheen: the Charlie lobe over the base (sheen color 0 = no sheen).
    Color sheen_color{0.f};                    ///< sheenColorFactor (linear)
    TextureRef sheen_color_texture;            ///< RGB, sRGB-encoded
    float sheen_roughness = 0.f;               ///< sheenRoughnessFactor
    TextureRef sheen_roughness_texture;        ///< A channel
    // KHR_materials_iridescence: a thin film replacing the Fresnel of the specular lobe.
    float iridescence = 0.f;                   ///< iridescenceFactor
    TextureRef iridescence_texture;            ///< R channel
    float iridescence_ior = 1.3f;              ///< iridescenceIor (of the film)
    float iridescence_thickness_min = 100.f;   ///< nm, texture value 0
    float iridescence_thickness_max = 400.f;   ///< nm, texture value 1 (and without a texture)
    TextureRef iridescence_thickness_texture;  ///< G channel
    // KHR_materials_anisotropy: an anisotropic highlight along a tangent-space direction.
    float anisotropy_strength = 0.f;           ///< [0, 1]
    float anisotropy_rotation = 0.f;           ///< radians, counter-clockwise from the tangent
    TextureRef anisotropy_texture;             ///< RG: direction in [-1, 1] (from [0, 1]), B: strength
    // KHR_materials_dispersion
    float dispersion = 0.f;                    ///< 20 / Abbe number; 0 = one ior for every channel
    // KHR_materials_diffuse_transmission: a diffuse BTDF sharing the diffuse lobe's weight.
    float diffuse_transmission = 0.f;          ///< diffuseTransmissionFactor
    TextureRef diffuse_transmission_texture;   ///< A channel
    Color diffuse_transmission_color{1.f};     ///< diffuseTransmissionColorFactor (linear)
    TextureRef diffuse_transmission_color_texture;  ///< RGB, sRGB-encoded
    // KHR_materials_pbrSpecularGlossiness: diffuseFactor/diffuseTexture are read into
    // base_color/base_color_texture, metallic is 0, roughness 1 - glossiness, F0 = specular.
    bool specular_glossiness = false;
    Color sg_specular{1.f};                    ///< specularFactor (linear)
    float glossiness = 1.f;                    ///< glossinessFactor
    TextureRef specular_glossiness_texture;    ///< RGB specular (sRGB-encoded), A glossiness (linear)

    /// True when one of the layered extensions above is active (clearcoat, sheen, iridescence,
    /// anisotropy, dispersion, diffuse transmission); specular-glossiness is not a layer.
    bool layered() const {
        return clearcoat > 0.f || sheen_color != Color(0.f) || iridescence > 0.f || anisotropy_strength > 0.f ||
               dispersion > 0.f || diffuse_transmission > 0.f;
    }

    // MaterialModel::Classic: Whitted's (1980) coefficients, used as given.
    WhittedCoeffs classic;
    TextureRef classic_color_texture;          ///< Classic: RGB multiplies kd and ka (checker or image)

private:
    template <class M>
    static auto slots(M& m) {
        return std::array{&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                          &m.occlusion_texture, &m.emissive_texture, &m.transmission_texture,
                          &m.specular_texture, &m.specular_color_texture, &m.clearcoat_texture,
                          &m.clearcoat_roughness_texture, &m.clearcoat_normal_texture, &m.sheen_color_texture,
                          &m.sheen_roughness_texture, &m.iridescence_texture, &m.iridescence_thickness_texture,
                          &m.anisotropy_texture, &m.diffuse_transmission_texture,
                          &m.diffuse_transmission_color_texture, &m.specular_glossiness_texture,
                          &m.classic_color_texture};
    }

public:
    /// Every texture slot, for code that treats them alike (analysis, scene-file includes).
    auto texture_slots() { return slots(*this); }
    auto texture_slots() const { return slots(*this); }
};

// ---------------------------------------------------------------------------------------------
// Lights and cameras

enum class LightType : uint8_t { Point, Spot, Directional };

/// How light falls off with distance d.
enum class Attenuation : uint8_t {
    InverseSquare,   ///< fat = 1/d^2, windowed by `range` when range > 0 (glTF KHR_lights_punctual)
    Classic,         ///< fat = min(1, 1/(c1 + c2 d + c3 d^2)) (Foley et al.; scene files)
    None             ///< fat = 1 (directional lights)
};

/// A punctual light in renderer units: `intensity * color` is the radiant intensity I such that a
/// surface at distance d facing the light receives I/d^2 (point/spot) or I (directional).
struct Light {
    std::string name;
    LightType type = LightType::Point;
    Color color{1.f};                 ///< linear RGB
    float intensity = 1.f;            ///< renderer units (see docs/lights.md)
    float range = 0.f;                ///< 0 = infinite
    float inner_cone = 0.f;           ///< spot: radians
    float outer_cone = kPi / 4.f;     ///< spot: radians
    Vec3d position;                   ///< world position (point, spot)
    Vec3d direction{0, 0, -1};        ///< world direction the light travels (spot, directional), unit
    Attenuation attenuation = Attenuation::InverseSquare;
    Vec3f classic_c{1.f, 0.f, 0.f};   ///< c1, c2, c3 for Attenuation::Classic
    bool is_default = false;          ///< added because the scene had no light
    bool from_environment = false;    ///< extracted from the environment (skipped where too dim to matter)
};

enum class CameraType : uint8_t { Perspective, Orthographic };

struct Camera {
    std::string name;
    CameraType type = CameraType::Perspective;
    double yfov = 0.8;                ///< perspective: vertical field of view, radians
    double aspect = 0.0;              ///< width / height from the file; 0 = not given
    double xmag = 1.0, ymag = 1.0;    ///< orthographic: half extents
    double znear = 1e-3;              ///< near clip distance (rays start here)
    double zfar = 0.0;                ///< 0 = infinite
    Mat4d world_from_camera;          ///< camera looks down -Z, +Y up (glTF convention)
    bool is_default = false;          ///< framed from the scene bounds because the file had none
};

// ---------------------------------------------------------------------------------------------
// Report of what an importer did

/// How an extension was handled.
enum class ExtensionSupport : uint8_t { Supported, Ignored, Refused };

struct ExtensionUse {
    std::string name;
    ExtensionSupport support = ExtensionSupport::Supported;
    bool required = false;            ///< listed in extensionsRequired
    std::string note;                 ///< e.g. "first frame / bind pose"
};

/// A glTF primitive whose geometry the file stores compressed (KHR_draco_mesh_compression,
/// EXT_meshopt_compression), as `whitted info` reports it.
struct CompressedPrimitive {
    std::string pointer;              ///< JSON pointer, "/meshes/0/primitives/1"
    std::string codec;                ///< "draco" or "meshopt"
    uint64_t compressed_bytes = 0;    ///< the streams' bytes in the file
    uint64_t decoded_bytes = 0;       ///< the accessors' data they decode to
};

// ---------------------------------------------------------------------------------------------
// Render settings a scene file may carry; command-line flags override them. Unset = the
// renderer's default.

struct SceneRenderSettings {
    std::optional<int> width, height;            ///< pixels
    std::optional<std::string> aa;               ///< center, corners, adaptive, stratified
    std::optional<float> aa_threshold;           ///< adaptive: contrast threshold
    std::optional<int> aa_depth;                 ///< adaptive: maximum subdivision depth
    std::optional<int> spp;                      ///< stratified: samples per pixel (k*k)
    std::optional<int> max_depth;                ///< maximum depth of the ray tree
    std::optional<float> min_weight;             ///< adaptive ray-tree depth cutoff (Hall & Greenberg)
    std::optional<Color> background;             ///< radiance of rays that hit nothing (linear)
    std::optional<Color> ambient;                ///< Ia (linear)
    std::optional<float> exposure;               ///< stops
    std::optional<bool> fresnel;                 ///< Schlick-weighted kr / kt
    std::optional<std::string> output;           ///< output file, relative to the scene file's folder
    std::optional<std::string> view;             ///< OCIO view
    std::optional<std::string> display;          ///< OCIO display
    std::optional<int> camera;                   ///< index into Scene::cameras
};

/// Whether the caller (command line, Python) set a setting itself, named by its scene-file key
/// ("width", "aa_threshold", "output", ...): such a setting wins over the file's. Empty = none.
using SettingGiven = std::function<bool(std::string_view key)>;

/// The command-line flag of a scene-file setting: "aa_threshold" -> "--aa-threshold".
inline std::string setting_flag(std::string_view key) {
    std::string flag = "--";
    for (const char c : key) flag += c == '_' ? '-' : c;
    return flag;
}

/// What a glTF file animates, for `whitted info`: one record per animation, skin and morphed mesh.
struct AnimationInfo {
    std::string name;                 ///< the file's name, or "animation <i>"
    float duration = 0.f;             ///< seconds: the last key time over its samplers
    size_t channels = 0;
    std::string interpolations;       ///< those its samplers use: "LINEAR", "STEP,CUBICSPLINE", ...
    bool posed = false;               ///< chosen for this import (--animation) and applied at Scene::time
};
struct SkinInfo {
    std::string name;                 ///< the file's name, or "skin <i>"
    size_t joints = 0;
    size_t meshes = 0;                ///< mesh instances it deforms in the imported scene
};
struct MorphInfo {
    std::string mesh;                 ///< the mesh's name, or "mesh <i>"
    size_t targets = 0;               ///< morph targets of each of its primitives
    std::vector<float> default_weights;  ///< mesh.weights (empty: 0 each)
};

// ---------------------------------------------------------------------------------------------

struct Scene {
    std::string source;               ///< file the scene came from
    std::vector<Mesh> meshes;
    std::vector<Instance> instances;
    std::vector<Sphere> spheres;
    std::vector<Quadric> quadrics;    ///< cylinders, cones and discs
    std::vector<Plane> planes;        ///< infinite planes (outside the acceleration structures)
    std::vector<Material> materials;  ///< never empty after import (a default material is added)
    std::vector<Texture> textures;
    std::vector<Light> lights;
    std::optional<Environment> environment;  ///< what rays that leave the scene see, and its light
    std::vector<Camera> cameras;
    std::vector<ExtensionUse> extensions;
    std::vector<CompressedPrimitive> compressed;  ///< glTF primitives stored compressed
    std::vector<std::string> warnings;  ///< each distinct warning once
    SceneRenderSettings settings;     ///< from a scene file; empty for glTF
    double time = 0.0;                ///< seconds: the moment the animated nodes, skins and morphs are posed at
    std::vector<AnimationInfo> animations;  ///< the glTF file's animations (posed or not)
    std::vector<SkinInfo> skins;
    std::vector<MorphInfo> morphs;
    std::vector<std::string> variants;  ///< the glTF file's KHR_materials_variants variants, in order
    std::string variant;                ///< the one applied (empty: the default materials)

    /// Geometry ids (see GeomKind): meshes, then spheres, then quadrics, then planes.
    uint32_t sphere_geom_id(size_t sphere) const { return uint32_t(meshes.size() + sphere); }
    uint32_t quadric_geom_id(size_t quadric) const { return uint32_t(meshes.size() + spheres.size() + quadric); }
    uint32_t plane_geom_id(size_t plane) const {
        return uint32_t(meshes.size() + spheres.size() + quadrics.size() + plane);
    }
    uint32_t geometry_count() const { return plane_geom_id(planes.size()); }
    GeomKind geom_kind(uint32_t geom) const {
        if (geom < meshes.size()) return GeomKind::Mesh;
        if (geom < quadric_geom_id(0)) return GeomKind::Sphere;
        return geom < plane_geom_id(0) ? GeomKind::Quadric : GeomKind::Plane;
    }
    /// The sphere, quadric or plane a geometry id of that kind names.
    const Sphere& sphere_of(uint32_t geom) const { return spheres[geom - meshes.size()]; }
    const Quadric& quadric_of(uint32_t geom) const { return quadrics[geom - quadric_geom_id(0)]; }
    const Plane& plane_of(uint32_t geom) const { return planes[geom - plane_geom_id(0)]; }
    /// Material of any geometry id.
    uint32_t geom_material(uint32_t geom) const {
        switch (geom_kind(geom)) {
            case GeomKind::Mesh: return meshes[geom].material;
            case GeomKind::Sphere: return sphere_of(geom).material;
            case GeomKind::Quadric: return quadric_of(geom).material;
            case GeomKind::Plane: break;
        }
        return plane_of(geom).material;
    }

    /// Adds a warning unless the same text was already recorded.
    void warn(const std::string& message);
    /// World-space vertices of triangle `prim` of instance `inst`, transformed in double from the
    /// mesh's float positions.
    void world_triangle(uint32_t inst, uint32_t prim, Vec3d out[3]) const {
        const Instance& in = instances[inst];
        const Mesh& m = meshes[in.mesh];
        for (int k = 0; k < 3; ++k)
            out[k] = in.world_from_object.apply_point(Vec3d(m.positions[m.indices[size_t(prim) * 3 + size_t(k)]]));
    }
    /// World-space bounds of all instances, spheres and quadrics (computed, not cached; planes are infinite
    /// and not included).
    Bounds3d world_bounds() const;
    /// Total triangles over instances (a mesh used twice counts twice).
    size_t instanced_triangle_count() const;
    size_t mesh_triangle_count() const;
};

}  // namespace whitted
