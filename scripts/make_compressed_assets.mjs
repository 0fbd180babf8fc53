// Writes the bundled compressed variants of glTF models (assets/gltf/<Model>/glTF-<Variant>/),
// with glTF Transform and the encoders it uses, from the npm registry. Run through
// scripts/make_compressed_assets.sh, which installs the pinned versions. See docs/gltf-support.md.
import { NodeIO } from '@gltf-transform/core';
import { ALL_EXTENSIONS, EXTMeshoptCompression } from '@gltf-transform/extensions';
import { draco, meshopt, textureCompress } from '@gltf-transform/functions';
import { MeshoptEncoder, MeshoptDecoder } from 'meshoptimizer';
import draco3d from 'draco3dgltf';
import sharp from 'sharp';
import { mkdirSync } from 'node:fs';
import { dirname } from 'node:path';

await MeshoptEncoder.ready;
await MeshoptDecoder.ready;
const io = new NodeIO().registerExtensions(ALL_EXTENSIONS).registerDependencies({
  'draco3d.encoder': await draco3d.createEncoderModule(),
  'draco3d.decoder': await draco3d.createDecoderModule(),
  'meshopt.encoder': MeshoptEncoder,
  'meshopt.decoder': MeshoptDecoder,
});

// Each variant: a transform of the document (in place).
const variants = {
  // KHR_draco_mesh_compression, edgebreaker, glTF Transform's default quantization
  // (position 14 bits, normal 10, texcoord 12, colour 8): lossy.
  Draco: async (doc) => doc.transform(draco({ method: 'edgebreaker' })),
  // EXT_meshopt_compression of the float attributes as they are: no quantization, no filters,
  // lossless.
  Meshopt: async (doc) => {
    doc.createExtension(EXTMeshoptCompression).setRequired(true)
      .setEncoderOptions({ method: EXTMeshoptCompression.EncoderMethod.QUANTIZE });
  },
  // EXT_meshopt_compression after KHR_mesh_quantization, with the OCTAHEDRAL/QUATERNION/
  // EXPONENTIAL filters (glTF Transform's "high" level): lossy.
  MeshoptFiltered: async (doc) => doc.transform(meshopt({ encoder: MeshoptEncoder, level: 'high' })),
  // EXT_texture_webp, lossy WebP at sharp's default quality, no PNG/JPEG fallback.
  WebP: async (doc) => doc.transform(textureCompress({ encoder: sharp, targetFormat: 'webp' })),
};

const [, , input, variant, output] = process.argv;
if (!input || !variants[variant] || !output) {
  console.error(`usage: make_compressed_assets.mjs <in.glb> <${Object.keys(variants).join('|')}> <out.glb>`);
  process.exit(2);
}
const doc = await io.read(input);
await variants[variant](doc);
mkdirSync(dirname(output), { recursive: true });
await io.write(output, doc);
