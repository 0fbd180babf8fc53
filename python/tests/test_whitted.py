"""The Python module against the library and the CLI (docs/python.md). Run by ctest (label python):
PYTHONPATH=build/release/python /usr/bin/python3 -m pytest python/tests"""
import os
import sys
import subprocess

import numpy as np
import pytest

import whitted

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ASSETS = os.path.join(ROOT, "assets")
DEFAULT_GLB = os.path.join(ASSETS, "scenes", "default.glb")
WHITTED1980 = os.path.join(ASSETS, "scenes", "whitted1980.json")
CLI = os.environ.get("WHITTED_EXE")


@pytest.fixture(scope="module")
def glb():
    return whitted.load(DEFAULT_GLB)


def test_info_is_what_whitted_info_prints(glb):
    info = glb.info()
    assert info["triangles"] > 1000 and info["lights"] >= 1 and info["cameras"] >= 1
    assert info["path"] == DEFAULT_GLB
    if CLI:
        out = subprocess.run([CLI, "info", DEFAULT_GLB], capture_output=True, text=True, check=True).stdout
        assert out == info["text"]


def test_scene_file_quadrics_are_counted_and_rendered():
    scene = whitted.load(os.path.join(ASSETS, "scenes", "quadrics.json"))
    info = scene.info()
    assert info["quadrics"] >= 8 and info["triangles"] == 0
    assert "cylinder[0]" in info["text"] and "disc[" in info["text"]
    image = whitted.render(scene, width=48, height=30, aa="center", threads=1).beauty
    assert image.shape == (30, 48, 3) and np.isfinite(image).all() and image.max() > 0.1


def test_bad_file_raises_whitted_error_naming_it(tmp_path):
    bad = tmp_path / "broken.gltf"
    # Three positions (36 bytes) declared in a 12-byte buffer.
    bad.write_text('{"asset": {"version": "2.0"}, "buffers": [{"byteLength": 12, "uri": '
                   '"data:application/octet-stream;base64,AAAAAAAAAAAAAAAA"}], '
                   '"bufferViews": [{"buffer": 0, "byteLength": 12}], "accessors": [{"bufferView": 0, '
                   '"componentType": 5126, "count": 3, "type": "VEC3"}], "meshes": [{"primitives": '
                   '[{"attributes": {"POSITION": 0}}]}], "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}')
    with pytest.raises(whitted.Error) as e:
        whitted.load(str(bad))
    assert "broken.gltf" in str(e.value)
    assert e.value.file == str(bad) and e.value.pointer == "/accessors/0/count"
    with pytest.raises(whitted.Error, match="missing.glb"):
        whitted.load(str(tmp_path / "missing.glb"))


def test_render_arrays_own_the_film_and_match_the_cli(glb, tmp_path):
    img = whitted.render(glb, width=96, aa="corners", aov=["depth", "normal", "prim_id"], threads=2)
    assert img.beauty.shape == (img.height, 96, 3) and img.beauty.dtype == np.float32
    assert img.aov["depth"].shape == (img.height, 96) and img.aov["normal"].shape == (img.height, 96, 3)
    assert img.aov["prim_id"].dtype == np.uint32
    assert not img.beauty.flags["OWNDATA"] and img.beauty.base is not None  # a view of the film's memory
    assert np.isfinite(img.beauty).all() and img.beauty.max() > 0
    assert img.stats["camera_rays"] > 0
    # The arrays outlive the Image object they came from.
    beauty = img.beauty
    del img
    assert beauty.sum() > 0
    if CLI:
        exr = tmp_path / "cli.exr"
        subprocess.run([CLI, "render", DEFAULT_GLB, "-o", str(exr), "--width", "96", "--aa", "corners", "--exr-float",
                        "--no-progress", "--log-level", "error"], check=True)
        assert np.array_equal(whitted.read_image(str(exr)), beauty)


def test_every_aa_mode_and_the_scene_files_settings(tmp_path):
    s = whitted.load(WHITTED1980)
    for aa in ("center", "corners", "adaptive", "stratified"):
        img = whitted.render(s, width=40, aa=aa, spp=4, threads=1)
        assert img.beauty.shape == (30, 40, 3)  # whitted1980.json is 4:3
    # Its settings fill what is not passed (as `whitted render` with no flags): its size.
    assert whitted.render(s, aa="center", max_depth=1).width == 800
    crop = whitted.render(s, width=40, aa="center", crop=(8, 4, 24, 20))
    assert crop.beauty.shape == (16, 16, 3) and crop.window == (8, 4, 24, 20)
    full = whitted.render(s, width=40, aa="center")
    assert np.array_equal(crop.beauty, full.beauty[4:20, 8:24])
    dark = whitted.render(s, width=40, aa="center", exposure=-2.0)
    assert np.allclose(dark.beauty, full.beauty * 0.25, rtol=1e-5, atol=1e-7)
    with pytest.raises(TypeError, match="no_such_setting"):
        whitted.render(s, no_such_setting=1)
    with pytest.raises(whitted.Error, match="aov"):
        whitted.render(s, aov=["colour"])


def test_texture_filter_keyword(glb):
    # default.glb's checkerboard: point samples (none) alias where MIP filtering averages.
    mip = whitted.render(glb, width=48, aa="center", texture_filter="mip")
    none = whitted.render(glb, width=48, aa="center", texture_filter="none")
    assert not np.array_equal(mip.beauty, none.beauty)
    assert np.array_equal(mip.beauty, whitted.render(glb, width=48, aa="center").beauty)  # mip is the default
    with pytest.raises(whitted.Error, match="texture-filter"):
        whitted.render(glb, width=8, texture_filter="bilinear")


def test_display_is_what_render_writes_to_png(glb, tmp_path):
    img = whitted.render(glb, width=64, aa="center")
    for view in ("Standard", "ACES 1.0 SDR-video"):
        png = tmp_path / "x.png"
        whitted.write(img, str(png), view=view)
        rgb8 = whitted.display(img.beauty, view=view)
        assert rgb8.dtype == np.uint8 and rgb8.shape == img.beauty.shape
        assert np.array_equal(np.round(whitted.read_image(str(png)) * 255).astype(np.uint8), rgb8)
    assert whitted.display(img.beauty, bits=16).dtype == np.uint16
    with pytest.raises(whitted.Error, match="view"):
        whitted.display(img.beauty, view="No such view")
    with pytest.raises(ValueError, match=r"beauty: expected shape \(H, W, 3\)"):
        whitted.display(np.zeros((4, 4)))


def test_write_exr_compression_keyword(glb, tmp_path):
    img = whitted.render(glb, width=32, aa="center")
    sizes = {}
    for method in ("zip", "none", "piz"):
        exr = tmp_path / f"{method}.exr"
        whitted.write(img, str(exr), exr_float=True, exr_compression=method)
        assert np.array_equal(whitted.read_image(str(exr)), img.beauty)  # lossless
        sizes[method] = exr.stat().st_size
    assert sizes["none"] > sizes["zip"]
    with pytest.raises(whitted.Error, match="unknown EXR compression 'b44'"):
        whitted.write(img, str(tmp_path / "bad.exr"), exr_compression="b44")


def test_write_tiff_compression_keyword(glb, tmp_path):
    img = whitted.render(glb, width=32, aa="center")
    sizes = {}
    for method in ("zip", "none", "zip:9"):
        tif = tmp_path / f"{method.replace(':', '_')}.tif"
        whitted.write(img, str(tif), tiff_compression=method)
        assert np.array_equal(whitted.read_image(str(tif)), whitted.read_image(str(tmp_path / "zip.tif")))
        sizes[method] = tif.stat().st_size
    assert sizes["none"] > sizes["zip"]
    with pytest.raises(whitted.Error, match="unknown TIFF compression 'lzw'"):
        whitted.write(img, str(tmp_path / "bad.tif"), tiff_compression="lzw")
    assert not (tmp_path / "bad.tif").exists()


def test_ray_queries_agree_across_accelerators(glb):
    rng = np.random.default_rng(7)
    n = 20000
    origins = rng.uniform(-1, 1, (n, 3)) + [0.0, 1.0, 4.0]
    directions = rng.normal(size=(n, 3))  # float64: converted
    ref = glb.intersect(origins, directions, accel="brute:precision=double", kind="reflection")
    assert ref.dtype.names == ("t", "u", "v", "prim", "geom", "inst")
    hit = np.isfinite(ref["t"])
    assert 0.05 * n < hit.sum() < n  # some rays hit, some miss
    for accel in ("embree", "bvh", "grid"):
        h = glb.intersect(origins.astype(np.float32), directions.astype(np.float32), accel=accel, kind="reflection")
        assert np.array_equal(np.isfinite(h["t"]), hit), accel
        assert np.allclose(h["t"][hit], ref["t"][hit], rtol=1e-4), accel
        same = (h["geom"] == ref["geom"]) & (h["prim"] == ref["prim"])
        assert same[hit].mean() > 0.999, accel  # exact ties at shared edges may name a neighbour
    # tmax cuts the ray: nothing beyond it.
    short = glb.intersect(origins, directions, tmax=0.5 * np.where(hit, ref["t"], 1.0), kind="reflection")
    assert not np.isfinite(short["t"][hit]).any()


def test_transmittance_is_zero_behind_opaque_and_one_in_the_open(glb):
    rng = np.random.default_rng(3)
    origins = rng.uniform(-1, 1, (5000, 3)) + [0.0, 1.0, 4.0]
    directions = rng.normal(size=(5000, 3))
    hits = glb.intersect(origins, directions, kind="shadow")
    tr = glb.transmittance(origins, directions)
    assert tr.shape == (5000, 3) and tr.dtype == np.float32
    missed = ~np.isfinite(hits["t"])
    assert (tr[missed] == 1).all()
    assert (tr[~missed] < 1).any(axis=1).all()  # every hit surface takes some light
    assert ((tr >= 0) & (tr <= 1)).all()


def test_wrong_shapes_and_dtypes_raise_value_error_naming_the_argument(glb):
    d = np.ones((5, 3))
    with pytest.raises(ValueError, match=r"origins: expected shape \(N, 3\), got \(5, 2\)"):
        glb.intersect(np.ones((5, 2)), d)
    with pytest.raises(ValueError, match=r"directions: expected shape \(5, 3\), got \(4, 3\)"):
        glb.intersect(np.ones((5, 3)), np.ones((4, 3)))
    with pytest.raises(ValueError, match="origins"):
        glb.transmittance(np.array([["a", "b", "c"]]), d[:1])
    with pytest.raises(ValueError, match=r"tmax: expected a number or shape \(5,\)"):
        glb.transmittance(d, d, tmax=np.ones(3))
    with pytest.raises(ValueError, match="kind"):
        glb.intersect(d, d, kind="sideways")
    with pytest.raises(whitted.Error, match="accelerator|unknown"):
        glb.intersect(d, d, accel="quadtree")


def test_import_render_and_png_do_not_load_openimageio(tmp_path):
    # A fresh interpreter: importing whitted, rendering with the bundled environment and writing
    # PNG, EXR, JPEG and TIFF never map OpenImageIO (docs/performance.md "Fixed cost of a run");
    # loading a scene whose environment is a PNG does (the image module reads it).
    code = (
        "import sys, whitted\n"
        "img = whitted.render(whitted.load(sys.argv[1]), width=16)\n"
        "for ext in ('png', 'exr', 'jpg', 'tif'): whitted.write(img, sys.argv[2] + '/a.' + ext)\n"
        "before = 'libOpenImageIO' in open('/proc/self/maps').read()\n"
        "whitted.load(sys.argv[1], environment=sys.argv[2] + '/a.png')\n"
        "print(before, 'libOpenImageIO' in open('/proc/self/maps').read())\n"
    )
    out = subprocess.run([sys.executable, "-c", code, DEFAULT_GLB, str(tmp_path)], capture_output=True, text=True,
                         env=dict(os.environ), check=True).stdout.split()
    assert out == ["False", "True"]
    assert all((tmp_path / ("a." + ext)).stat().st_size > 0 for ext in ("png", "exr", "jpg", "tif"))


def test_load_poses_an_animated_file_at_a_time():
    # AnimatedTriangle turns about +Z over one second: a quarter turn at 0.25 s moves the image.
    tri = os.path.join(ASSETS, "gltf", "AnimatedTriangle", "glTF", "AnimatedTriangle.gltf")
    at0 = whitted.render(whitted.load(tri, default_camera=True), width=32, height=32).beauty
    at = whitted.render(whitted.load(tri, time=0.25), width=32, height=32).beauty
    assert not np.array_equal(at0, at)
    again = whitted.render(whitted.load(tri, time=0.25, animation="0"), width=32, height=32).beauty
    assert np.array_equal(at, again)
    assert "time=0.25s" in whitted.load(tri, time=0.25).info()["text"]
    with pytest.raises(whitted.Error, match="no animation 'walk'"):
        whitted.load(tri, animation="walk")
    with pytest.raises(whitted.Error, match="time"):
        whitted.load(tri, time=float("nan"))


def test_load_takes_a_material_variant():
    # Box has no KHR_materials_variants: naming one is an error naming the file (the mapping
    # itself is tested in C++, GltfVariants.*).
    box = os.path.join(ASSETS, "gltf", "Box", "glTF-Binary", "Box.glb")
    assert whitted.load(box, variant="").info()["text"]
    with pytest.raises(whitted.Error, match="Box.glb.*variant 'beach': the file has no KHR_materials_variants"):
        whitted.load(box, variant="beach")


def test_env_occlusion_keyword():
    # Box under the furnace: occlusion traces rays (off traces none), both give a finite image;
    # a bad value is a WhittedError naming the keyword.
    box = os.path.join(ASSETS, "gltf", "Box", "glTF-Binary", "Box.glb")
    scene = whitted.load(box, environment="furnace")
    on = whitted.render(scene, width=32, height=32, env_occlusion=16)
    off = whitted.render(scene, width=32, height=32, env_occlusion="off")
    assert on.stats["occlusion_rays"] > 0
    assert off.stats["occlusion_rays"] == 0
    assert np.isfinite(on.beauty).all()
    with pytest.raises(whitted.Error, match="env_occlusion"):
        whitted.render(scene, width=8, env_occlusion="lots")
