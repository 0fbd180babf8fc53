// The extension table: Khronos registry (ratified and release-candidate KHR_) plus the common
// EXT_/vendor extensions seen in the wild. Keep docs/gltf-support.md in step with it.

#include "importers/gltf_extensions.h"

#include <array>
#include <string_view>

namespace whitted::gltf {

namespace {

struct Entry {
    std::string_view name;
    ExtensionSupport support;
    bool refuse_if_required;
    std::string_view note;
};

constexpr ExtensionSupport S = ExtensionSupport::Supported;
constexpr ExtensionSupport I = ExtensionSupport::Ignored;

// refuse_if_required: true where ignoring the extension would lose data the file cannot be
// shown without (compressed geometry, texture formats without a core fallback); false where
// the file still renders recognisably without it (appearance layers, metadata).
constexpr std::array kTable = {
    Entry{"KHR_lights_punctual", S, false, "point, spot and directional lights (docs/lights.md)"},
    Entry{"KHR_materials_emissive_strength", S, false, "emissiveStrength multiplies the emission"},
    Entry{"KHR_materials_ior", S, false, "index of refraction"},
    Entry{"KHR_materials_specular", S, false, "specular factor/color and their textures"},
    Entry{"KHR_materials_transmission", S, false, "transmission factor and texture"},
    Entry{"KHR_materials_unlit", S, false, "base color shown as is"},
    Entry{"KHR_materials_volume", S, false,
          "thicknessFactor > 0 makes a volume; attenuation color/distance; thickness texture not used"},
    Entry{"KHR_mesh_quantization", S, false, "integer and normalized vertex attributes"},
    Entry{"KHR_texture_transform", S, false, "offset, rotation, scale, texCoord override on every textureInfo"},
    Entry{"EXT_mesh_gpu_instancing", S, false, "TRANSLATION/ROTATION/SCALE make one instance each"},
    Entry{"KHR_materials_clearcoat", S, false, "coat factor and roughness with their textures, coat normal map"},
    Entry{"KHR_materials_sheen", S, false, "sheen color and roughness with their textures"},
    Entry{"KHR_materials_iridescence", S, false, "thin-film factor, ior, thickness range and their textures"},
    Entry{"KHR_materials_anisotropy", S, false, "strength, rotation and direction texture; tangents generated"},
    Entry{"KHR_materials_dispersion", S, false, "dispersion (20 / Abbe number)"},
    Entry{"KHR_materials_diffuse_transmission", S, false, "factor and color with their textures"},
    Entry{"KHR_materials_variants", S, false, "--variant NAME applies a variant's materials; default materials otherwise"},
    Entry{"KHR_materials_pbrSpecularGlossiness", S, false,
          "diffuse, specular, glossiness and their textures; replaces pbrMetallicRoughness"},
    Entry{"KHR_xmp", I, false, "metadata not read"},
    Entry{"KHR_xmp_json_ld", I, false, "metadata not read"},
    Entry{"KHR_animation_pointer", S, false,
          "pointers to node TRS and weights, camera yfov, light color and intensity, core and extension material "
          "factors and core textures' KHR_texture_transform applied; other targets warn once each"},
    Entry{"KHR_texture_basisu", I, true, "KTX2/Basis images not decoded; the core texture source is used when present"},
    Entry{"EXT_texture_webp", S, false, "WebP images decoded (libwebp), preferred over the core source"},
    Entry{"EXT_texture_avif", I, true, "AVIF images not decoded; the core texture source is used when present"},
    Entry{"MSFT_texture_dds", I, true, "DDS images not decoded; the core texture source is used when present"},
    Entry{"KHR_draco_mesh_compression", S, false, "decoded (Draco): every attribute by its id, and the indices"},
    Entry{"EXT_meshopt_compression", S, false, "decoded (meshoptimizer): ATTRIBUTES, TRIANGLES, INDICES; OCTAHEDRAL, QUATERNION, EXPONENTIAL filters"},
    Entry{"EXT_lights_image_based", I, false, "no image-based lighting"},
    Entry{"MSFT_lod", I, false, "the node's own (highest detail) mesh is used"},
    Entry{"KHR_materials_volume_scatter", I, false, "no scattering inside volumes (attenuation only)"},
    Entry{"KHR_node_visibility", I, true, "every node is shown"},
    Entry{"EXT_lights_ies", I, false, "IES light profiles not read"},
    Entry{"MSFT_packing_normalRoughnessMetallic", I, true, "packed textures not read; core textures used"},
    Entry{"MSFT_packing_occlusionRoughnessMetallic", I, true, "packed textures not read; core textures used"},
    Entry{"CESIUM_primitive_outline", I, false, "outlines not drawn"},
    Entry{"ADOBE_materials_thin_transparency", I, false, "core / KHR_materials_transmission values used"},
    Entry{"KHR_techniques_webgl", I, true, "custom shaders not supported"},
    Entry{"KHR_materials_cmnBlinnPhong", I, true, "not supported"},
};

}  // namespace

ExtensionPolicy extension_policy(const std::string& name) {
    for (const Entry& e : kTable)
        if (e.name == name) return {e.support, e.refuse_if_required, std::string(e.note), true};
    return {ExtensionSupport::Ignored, true, "unknown extension", false};
}

}  // namespace whitted::gltf
