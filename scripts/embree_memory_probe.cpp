// Bytes per triangle of Embree 3 structures over the 1,002,528-triangle grid of
// scripts/make_compressed_assets.mjs (grid:708), built the way embree_accel.cpp builds a mesh:
// shared vertex and index buffers, one instance in a top-level scene. Prints the device memory
// monitor's count after the build (what `whitted render` reports as the accelerator's bytes) and
// single-ray throughput for a fixed camera; Embree's own breakdown (nodes, leaves, allocator)
// with the device config "verbose=2". Not part of the build (docs/measurements/performance.md):
//   g++ -O2 -std=c++17 scripts/embree_memory_probe.cpp -lembree3 -o /tmp/embree_memory_probe
//   /tmp/embree_memory_probe [device-config] [flags: 1 robust, 2 compact] [quality 0-2] [n] [quads 0/1]
#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

static std::atomic<long> g_bytes{0};
static bool monitor(void*, ssize_t bytes, bool) {
    g_bytes += bytes;
    return true;
}

int main(int argc, char** argv) {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    const char* config = argc > 1 ? argv[1] : "";
    const int flags = argc > 2 ? std::atoi(argv[2]) : 1;
    const int quality = argc > 3 ? std::atoi(argv[3]) : RTC_BUILD_QUALITY_MEDIUM;
    const int n = argc > 4 ? std::atoi(argv[4]) : 708;
    const bool quads = argc > 5 && std::atoi(argv[5]);

    // The grid: (n + 1)^2 vertices of a height field, 2 n^2 triangles (or n^2 quads), padded.
    const int v = n + 1;
    std::vector<float> pos(size_t(v) * v * 3 + 4, 0.f);
    for (int j = 0; j < v; ++j)
        for (int i = 0; i < v; ++i) {
            const size_t k = size_t(j) * v + i;
            const float x = float(i) / n - 0.5f, z = float(j) / n - 0.5f;
            pos[3 * k] = x, pos[3 * k + 1] = 0.05f * std::sin(9 * x) * std::cos(7 * z), pos[3 * k + 2] = z;
        }
    std::vector<unsigned> idx;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const unsigned a = j * v + i;
            if (quads) idx.insert(idx.end(), {a, a + v, a + v + 1, a + 1});
            else idx.insert(idx.end(), {a, a + v, a + 1, a + 1, a + v, a + v + 1});
        }
    const size_t triangles = size_t(2) * n * n;

    RTCDevice device = rtcNewDevice(config);
    if (!device) return std::printf("cannot create device '%s'\n", config), 1;
    rtcSetDeviceMemoryMonitorFunction(device, monitor, nullptr);
    const RTCSceneFlags scene_flags = RTCSceneFlags(((flags & 1) ? RTC_SCENE_FLAG_ROBUST : 0) |
                                                    ((flags & 2) ? RTC_SCENE_FLAG_COMPACT : 0));
    const auto start = std::chrono::steady_clock::now();
    RTCGeometry g = rtcNewGeometry(device, quads ? RTC_GEOMETRY_TYPE_QUAD : RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, pos.data(), 0, 12, size_t(v) * v);
    const unsigned per = quads ? 4 : 3;
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, quads ? RTC_FORMAT_UINT4 : RTC_FORMAT_UINT3, idx.data(),
                               0, per * sizeof(unsigned), idx.size() / per);
    rtcCommitGeometry(g);
    RTCScene mesh = rtcNewScene(device);
    rtcSetSceneBuildQuality(mesh, RTCBuildQuality(quality));
    rtcSetSceneFlags(mesh, scene_flags);
    rtcAttachGeometryByID(mesh, g, 0);
    rtcReleaseGeometry(g);
    rtcCommitScene(mesh);
    RTCScene top = rtcNewScene(device);
    rtcSetSceneBuildQuality(top, RTCBuildQuality(quality));
    rtcSetSceneFlags(top, scene_flags);
    RTCGeometry inst = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, mesh);
    const float xfm[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
    rtcCommitGeometry(inst);
    rtcAttachGeometryByID(top, inst, 0);
    rtcReleaseGeometry(inst);
    rtcCommitScene(top);
    const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) return std::printf("Embree error\n"), 1;

    // Single rays from above the grid, 3 x 1024^2; hits and the sum of t to compare variants.
    const int w = 1024;
    long hits = 0;
    double sum_t = 0.0;
    const auto trace_start = std::chrono::steady_clock::now();
    for (int rep = 0; rep < 3; ++rep)
        for (int y = 0; y < w; ++y)
            for (int x = 0; x < w; ++x) {
                RTCIntersectContext context;
                rtcInitIntersectContext(&context);
                RTCRayHit rh{};
                const float d[3] = {(x + 0.5f) / w - 0.5f, -0.6f + (y + 0.5f) / w - 0.5f, 1.f};
                const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                rh.ray.org_y = 0.8f, rh.ray.org_z = -1.f;
                rh.ray.dir_x = d[0] / len, rh.ray.dir_y = d[1] / len, rh.ray.dir_z = d[2] / len;
                rh.ray.tfar = 1e30f, rh.ray.mask = ~0u;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(top, &context, &rh);
                if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) ++hits, sum_t += rh.ray.tfar;
            }
    const double trace = std::chrono::duration<double>(std::chrono::steady_clock::now() - trace_start).count();
    std::printf("config='%s' flags=%d quality=%d %s triangles=%zu bytes=%ld B/triangle=%.2f build=%.3fs "
                "single rays %.2f Mrays/s hits=%ld sum_t=%.6f\n",
                config, flags, quality, quads ? "quads" : "triangles", triangles, g_bytes.load(),
                double(g_bytes.load()) / double(triangles), build, 3.0 * w * w / trace / 1e6, hits, sum_t);
    rtcReleaseScene(top);
    rtcReleaseScene(mesh);
    rtcReleaseDevice(device);
}
