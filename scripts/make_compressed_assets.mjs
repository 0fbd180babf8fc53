// Writes the bundled compressed variants of glTF models (assets/gltf/<Model>/glTF-<Variant>/),
// with glTF Transform and the encoders it uses, from the npm registry. Run through
// scripts/make_compressed_assets.sh, which installs the pinned versions. See docs/gltf-support.md.
import { Document, NodeIO } from '@gltf-transform/core';
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

// A single mesh of 2*n*n triangles: a height field over an n x n grid of quads with normals and
// texture coordinates, one node, the default material (the large load-time model).
function grid(n) {
  const doc = new Document();
  const buffer = doc.createBuffer();
  const v = n + 1;
  const pos = new Float32Array(v * v * 3), nor = new Float32Array(v * v * 3), uv = new Float32Array(v * v * 2);
  const height = (x, z) => 0.05 * Math.sin(9 * x) * Math.cos(7 * z);
  for (let j = 0; j < v; ++j) {
    for (let i = 0; i < v; ++i) {
      const k = j * v + i, x = i / n - 0.5, z = j / n - 0.5;
      pos.set([x, height(x, z), z], 3 * k);
      const dx = 0.45 * Math.cos(9 * x) * Math.cos(7 * z), dz = -0.35 * Math.sin(9 * x) * Math.sin(7 * z);
      const l = Math.hypot(dx, 1, dz);
      nor.set([-dx / l, 1 / l, -dz / l], 3 * k);
      uv.set([i / n, j / n], 2 * k);
    }
  }
  const idx = new Uint32Array(n * n * 6);
  for (let j = 0, t = 0; j < n; ++j) {
    for (let i = 0; i < n; ++i, t += 6) {
      const a = j * v + i;
      idx.set([a, a + v, a + 1, a + 1, a + v, a + v + 1], t);
    }
  }
  const acc = (type, array) => doc.createAccessor().setType(type).setArray(array).setBuffer(buffer);
  const prim = doc.createPrimitive().setIndices(acc('SCALAR', idx))
    .setAttribute('POSITION', acc('VEC3', pos)).setAttribute('NORMAL', acc('VEC3', nor))
    .setAttribute('TEXCOORD_0', acc('VEC2', uv)).setMaterial(doc.createMaterial());
  const node = doc.createNode().setMesh(doc.createMesh().addPrimitive(prim));
  doc.createScene().addChild(node);
  return doc;
}

const [, , input, variant, output] = process.argv;
if (!input || !(variants[variant] || variant === 'Plain') || !output) {
  console.error(`usage: make_compressed_assets.mjs <in.glb|grid:N> <Plain|${Object.keys(variants).join('|')}> <out.glb>`);
  process.exit(2);
}
const doc = input.startsWith('grid:') ? grid(Number(input.slice(5))) : await io.read(input);
if (variant !== 'Plain') await variants[variant](doc);
mkdirSync(dirname(output), { recursive: true });
await io.write(output, doc);
