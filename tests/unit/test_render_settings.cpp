// Scene-file settings merged with the caller's (apply_scene_settings, apply_scene_output_settings):
// what the caller set wins, the rest comes from the file, and one size flag keeps the aspect ratio.

#include <cmath>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "integrator/render_settings.h"
#include "output/image_output.h"

namespace whitted {
namespace {

/// A SettingGiven that answers true for exactly `keys`.
SettingGiven given_keys(std::set<std::string> keys) {
    return [keys = std::move(keys)](std::string_view key) { return keys.count(std::string(key)) > 0; };
}

SceneRenderSettings every_render_setting() {
    SceneRenderSettings s;
    s.width = 80;
    s.height = 60;
    s.camera = 1;
    s.aa = "stratified";
    s.aa_threshold = 0.25f;
    s.aa_depth = 2;
    s.spp = 9;
    s.max_depth = 7;
    s.min_weight = 0.125f;
    s.background = Color(0.1f, 0.2f, 0.3f);
    s.ambient = Color(0.4f);
    s.exposure = 1.5f;
    s.fresnel = true;
    return s;
}

TEST(RenderSettings, NothingGivenTakesEverySettingOfTheFile) {
    RenderSettings rs;
    apply_scene_settings(every_render_setting(), rs);
    EXPECT_EQ(rs.width, 80);
    EXPECT_EQ(rs.height, 60);
    EXPECT_EQ(rs.camera, 1);
    EXPECT_EQ(rs.aa.mode, AaMode::Stratified);
    EXPECT_EQ(rs.aa.threshold, 0.25f);
    EXPECT_EQ(rs.aa.depth, 2);
    EXPECT_EQ(rs.aa.spp, 9);
    EXPECT_EQ(rs.integrator.max_depth, 7);
    EXPECT_EQ(rs.integrator.min_weight, 0.125f);
    EXPECT_EQ(rs.integrator.background, Color(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(rs.integrator.ambient, Color(0.4f));
    EXPECT_EQ(rs.exposure, std::exp2(1.5f));  // stops in the file, a linear scale in the settings
    EXPECT_TRUE(rs.integrator.fresnel);
}

TEST(RenderSettings, WhatTheCallerSetWinsAndTheRestComesFromTheFile) {
    RenderSettings rs;
    rs.integrator.max_depth = 3;
    rs.integrator.background = Color(1.f);
    rs.aa.mode = AaMode::Corners;
    apply_scene_settings(every_render_setting(), rs, given_keys({"max_depth", "background", "aa"}));
    EXPECT_EQ(rs.integrator.max_depth, 3);
    EXPECT_EQ(rs.integrator.background, Color(1.f));
    EXPECT_EQ(rs.aa.mode, AaMode::Corners);
    EXPECT_EQ(rs.aa.spp, 9);
    EXPECT_EQ(rs.integrator.ambient, Color(0.4f));
    EXPECT_EQ(rs.camera, 1);
}

TEST(RenderSettings, UnsetFileValuesKeepTheCallersSettings) {
    RenderSettings rs;
    rs.width = 320;
    rs.integrator.ambient = Color(0.5f);
    apply_scene_settings(SceneRenderSettings{}, rs);
    EXPECT_EQ(rs.width, 320);
    EXPECT_EQ(rs.height, 0);
    EXPECT_EQ(rs.integrator.ambient, Color(0.5f));
}

/// The size after merging a file's width/height (0 = not in the file) with the caller's (0 = not
/// set), as "WxH".
std::string merged_size(int file_width, int file_height, int width, int height) {
    SceneRenderSettings s;
    if (file_width) s.width = file_width;
    if (file_height) s.height = file_height;
    RenderSettings rs;
    rs.width = width;
    rs.height = height;
    std::set<std::string> keys;
    if (width) keys.insert("width");
    if (height) keys.insert("height");
    apply_scene_settings(s, rs, given_keys(keys));
    return std::to_string(rs.width) + "x" + std::to_string(rs.height);
}

// 0 in the result = completed from the camera's aspect ratio when the image size is resolved.
TEST(RenderSettings, ImageSizeKeepsTheAspectRatioOfTheFileOrTheCamera) {
    // No size set: the file's.
    EXPECT_EQ(merged_size(800, 600, 0, 0), "800x600");
    EXPECT_EQ(merged_size(800, 0, 0, 0), "800x0");
    EXPECT_EQ(merged_size(0, 0, 0, 0), "0x0");
    // Both set: the caller's, whatever the file says.
    EXPECT_EQ(merged_size(800, 600, 100, 100), "100x100");
    // One set, the file gives both: the file's aspect ratio, rounded to the nearest pixel.
    EXPECT_EQ(merged_size(800, 600, 400, 0), "400x300");
    EXPECT_EQ(merged_size(800, 600, 0, 300), "400x300");
    EXPECT_EQ(merged_size(640, 480, 101, 0), "101x76");
    EXPECT_EQ(merged_size(1000, 1, 10, 0), "10x1");  // at least one pixel
    // One set, the file gives one or none: the camera's aspect ratio.
    EXPECT_EQ(merged_size(800, 0, 0, 300), "0x300");
    EXPECT_EQ(merged_size(0, 600, 400, 0), "400x0");
    EXPECT_EQ(merged_size(0, 0, 400, 0), "400x0");
}

TEST(RenderSettings, OutputPathIsRelativeToTheSceneFileAndFlagsWin) {
    SceneRenderSettings s;
    s.output = "renders/out.png";
    s.view = "Raw";
    s.display = "sRGB";
    std::string path = "whitted.png";
    OutputSettings os;
    apply_scene_output_settings(s, "/scenes/room.json", path, os);
    EXPECT_EQ(path, "/scenes/renders/out.png");
    EXPECT_EQ(os.color.view, "Raw");
    EXPECT_EQ(os.color.display, "sRGB");

    s.output = "/tmp/abs.exr";
    apply_scene_output_settings(s, "/scenes/room.json", path, os);
    EXPECT_EQ(path, "/tmp/abs.exr");

    path = "mine.png";
    OutputSettings mine;
    apply_scene_output_settings(s, "/scenes/room.json", path, mine, given_keys({"output", "view"}));
    EXPECT_EQ(path, "mine.png");
    EXPECT_EQ(mine.color.view, "Standard");
    EXPECT_EQ(mine.color.display, "sRGB");
}

}  // namespace
}  // namespace whitted
