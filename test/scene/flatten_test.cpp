#include "scene/flatten.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "scene/reader.h"
#include "test_util.h"

namespace dayflux {
namespace {

double TriangleArea(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

bool InTriangle(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    // In the plane z = const (the test polygons lie in it).
    auto cross = [](const Vec3 &o, const Vec3 &x, const Vec3 &y) {
        return (x[0] - o[0]) * (y[1] - o[1]) - (x[1] - o[1]) * (y[0] - o[0]);
    };
    const double d1 = cross(a, b, p), d2 = cross(b, c, p), d3 = cross(c, a, p);
    return (d1 >= 0 && d2 >= 0 && d3 >= 0) || (d1 <= 0 && d2 <= 0 && d3 <= 0);
}

// The triangles cover exactly what RADIANCE's inside test calls inside: checked at random points,
// and by area.
void ExpectCoversPolygon(const std::vector<Vec3> &v, double area) {
    const auto tris = TriangulatePolygon(v);
    double sum = 0;
    for (const auto &t : tris) sum += TriangleArea(v[t[0]], v[t[1]], v[t[2]]);
    EXPECT_NEAR(sum, area, 1e-9 * area);
    const Vec3 n = PolygonNormal(v);
    for (const auto &t : tris) {  // every triangle keeps the polygon's winding
        const Vec3 tn = PolygonNormal({v[t[0]], v[t[1]], v[t[2]]});
        EXPECT_GT(tn[0] * n[0] + tn[1] * n[1] + tn[2] * n[2], 0);
    }
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.2, 1.2);
    for (int i = 0; i < 4000; ++i) {
        const Vec3 p{u(rng), u(rng), 0.5};
        bool in_tri = false;
        for (const auto &t : tris) in_tri |= InTriangle(p, v[t[0]], v[t[1]], v[t[2]]);
        ASSERT_EQ(in_tri, InsidePolygon(v, p)) << p[0] << " " << p[1];
    }
}

TEST(Polygons, ConvexConcaveAndStar) {
    ExpectCoversPolygon({{-1, -1, .5}, {1, -1, .5}, {1, 1, .5}, {-1, 1, .5}}, 4);
    // An L shape (concave), clockwise.
    ExpectCoversPolygon(
        {{-1, -1, .5}, {-1, 1, .5}, {0, 1, .5}, {0, 0, .5}, {1, 0, .5}, {1, -1, .5}}, 3);
    std::vector<Vec3> star;
    for (int k = 0; k < 14; ++k) {
        const double a = 2 * M_PI * k / 14, r = k % 2 ? 0.4 : 1.0;
        star.push_back({r * std::cos(a), r * std::sin(a), .5});
    }
    // Star area: 14 triangles between centre, outer and inner points.
    const double area = 14 * 0.5 * 1.0 * 0.4 * std::sin(2 * M_PI / 14);
    ExpectCoversPolygon(star, area);
}

TEST(Polygons, HoleJoinedByASeamAsOconvSeesIt) {
    // A 2 x 2 square with a 1 x 1 hole, joined by a seam from (1,0) to (0.5,0): the way RADIANCE
    // users (and obj2rad) write holes, the hole running against the outline.
    const std::vector<Vec3> v = {{-1, -1, .5},  {1, -1, .5},    {1, 0, .5},    {.5, 0, .5},
                                 {.5, -.5, .5}, {-.5, -.5, .5}, {-.5, .5, .5}, {.5, .5, .5},
                                 {.5, 0, .5},   {1, 0, .5},     {1, 1, .5},    {-1, 1, .5}};
    ExpectCoversPolygon(v, 3);
}

// The same hole written running the same way as its outline (as the tutorial room's south wall
// is): RADIANCE's even-odd rule still makes it a hole. Two holes in one outline too.
TEST(Polygons, HolesEitherWayAndSeveral) {
    const std::vector<Vec3> same = {{-1, -1, .5}, {1, -1, .5},   {1, 0, .5},     {.5, 0, .5},
                                    {.5, .5, .5}, {-.5, .5, .5}, {-.5, -.5, .5}, {.5, -.5, .5},
                                    {.5, 0, .5},  {1, 0, .5},    {1, 1, .5},     {-1, 1, .5}};
    ExpectCoversPolygon(same, 3);
    const std::vector<Vec3> two = {{-1, -1, .5},  {-.8, -.8, .5}, {-.2, -.8, .5}, {-.2, .8, .5},
                                   {-.8, .8, .5}, {-.8, -.8, .5}, {-1, -1, .5},   {1, -1, .5},
                                   {.8, -.8, .5}, {.8, .8, .5},   {.2, .8, .5},   {.2, -.8, .5},
                                   {.8, -.8, .5}, {1, -1, .5},    {1, 1, .5},     {-1, 1, .5}};
    ExpectCoversPolygon(two, 4 - 2 * 0.6 * 1.6);
}

TEST(Polygons, DegeneratePolygonsGiveNoTriangles) {
    EXPECT_TRUE(TriangulatePolygon({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}).empty());
    EXPECT_TRUE(TriangulatePolygon({{0, 0, 0}, {1, 0, 0}}).empty());
}

TEST(Flatten, TransformsAndShapesFromAScene) {
    Scene s;
    SceneReader r(&s);
    r.ReadText(
        "void plastic m 0 0 5 .5 .5 .5 0 0\n"
        "m polygon floor 0 0 12 0 0 0 2 0 0 2 3 0 0 3 0\n"
        "m sphere ball 0 0 4 1 1 1 .5\n"
        "m ring disk 0 0 8 0 0 2 0 0 -1 0 .3\n"
        "void glow sky 0 0 4 1 1 1 0\nsky source dome 0 0 4 0 0 1 180\n",
        "t.rad");
    s.objects[1].xf.m[12] = 10;  // as if moved by xform -t 10 0 0
    s.objects[1].xf.identity = false;
    FlatScene f = Flatten(std::move(s));
    ASSERT_EQ(f.triangles.size(), 2u);
    double area = 0;
    for (const auto &t : f.triangles)
        area += TriangleArea(f.vertices[t[0]], f.vertices[t[1]], f.vertices[t[2]]);
    EXPECT_NEAR(area, 6, 1e-12);
    EXPECT_EQ(f.vertices[f.triangles[0][0]][0] >= 10, true);
    EXPECT_EQ(f.triangle_object[0], 1);
    ASSERT_EQ(f.shapes.size(), 3u);
    EXPECT_EQ(f.shapes[0].kind, AnalyticShape::kSphere);
    EXPECT_EQ(f.shapes[0].r0, .5);
    EXPECT_EQ(f.shapes[1].kind, AnalyticShape::kRing);
    EXPECT_EQ(f.shapes[2].kind, AnalyticShape::kSource);
    EXPECT_EQ(f.shapes[2].r0, 180);
}

TEST(Flatten, TutorialRoomIsWatertightEnoughToCount) {
    const auto cwd = std::filesystem::current_path();
    std::filesystem::current_path(test::DataDir() / "scene/models/room");
    Scene s =
        ReadScene({"materials.rad", "room.rad", "objects/Glazing.rad", "skyDomes/skyglow.rad"});
    std::filesystem::current_path(cwd);
    FlatScene f = Flatten(std::move(s));
    EXPECT_EQ(f.shapes.size(), 2u);  // the sky and ground sources
    // Floor area of the 20 ft x 20 ft room: triangles of the "Floor" polygon sum to it.
    double floor = 0;
    for (size_t i = 0; i < f.triangles.size(); ++i)
        if (f.scene.objects[f.triangle_object[i]].modifier_name == "Floor") {
            const auto &t = f.triangles[i];
            floor += TriangleArea(f.vertices[t[0]], f.vertices[t[1]], f.vertices[t[2]]);
        }
    EXPECT_NEAR(floor, 6.096 * 6.096, 1e-3);
}

}  // namespace
}  // namespace dayflux

namespace dayflux {
namespace {

// A RADIANCE mesh made by obj2mesh (test/data/scene/mesh: box.obj, box.mat -> box.rtm).
TEST(Flatten, MeshFromObj2mesh) {
    setenv("RAYPATH", (test::DataDir() / "scene/mesh").c_str(), 1);
    Scene s;
    SceneReader r(&s);
    r.ReadText("void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey mesh box 5 box.rtm -t 2 0 0 0 0\n",
               "t.rad");
    FlatScene f = Flatten(std::move(s));
    unsetenv("RAYPATH");
    ASSERT_EQ(f.triangles.size(), 12u);
    double area = 0;
    int red = 0;
    for (size_t i = 0; i < f.triangles.size(); ++i) {
        const auto &t = f.triangles[i];
        area += TriangleArea(f.vertices[t[0]], f.vertices[t[1]], f.vertices[t[2]]);
        ASSERT_GE(f.triangle_material[i], 0);
        red += f.scene.objects[f.triangle_material[i]].name == "red";
        for (int k = 0; k < 3; ++k) {
            const Vec3 &v = f.vertices[t[k]];
            // Corners of the unit box moved by 2 in x, to the mesh's quantisation (~1e-9).
            EXPECT_NEAR(v[0] - 2, std::round(v[0] - 2), 1e-8);
            EXPECT_TRUE(v[0] > 1.9 && v[0] < 3.1);
        }
    }
    EXPECT_NEAR(area, 6, 1e-7);
    EXPECT_EQ(red, 2);
    EXPECT_EQ(f.triangle_object[0], 1);
}

// A damaged mesh claiming 10^8 patches fails at the end of its data, without first making room
// for them all (2.4 GB, as it once did).
TEST(Flatten, DamagedMeshesGetMessages) {
    test::TempDir tmp;
    const std::string box = test::ReadFile(test::DataDir() / "scene/mesh/box.rtm");
    // The end of the materials (type -1), the patch count (1) and the first patch's flags.
    const std::string mark("\xff\0\0\0\x01\x01", 6);
    const size_t at = box.find(mark);
    ASSERT_NE(at, std::string::npos);
    std::string many = box;
    many.replace(at + 1, 4, std::string("\x05\xf5\xe1\x00", 4));
    test::WriteFile(tmp.path() / "many.rtm", many);
    setenv("RAYPATH", tmp.path().c_str(), 1);
    Scene s;
    SceneReader r(&s);
    r.ReadText("void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey mesh box 1 many.rtm 0 0\n", "t.rad");
    std::string error;
    try {
        Flatten(std::move(s));
    } catch (const UserError &e) {
        error = e.what();
    }
    unsetenv("RAYPATH");
    EXPECT_NE(error.find("many.rtm: truncated mesh file"), std::string::npos) << error;
}

TEST(Flatten, BadInstanceTransformNamesItsPlace) {
    Scene s;
    SceneReader r(&s);
    r.ReadText("void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey mesh box 5 box.rtm -t 2 x 0 0 0\n",
               "t.rad");
    try {
        Flatten(std::move(s));
        ADD_FAILURE() << "no error";
    } catch (const UserError &e) {
        EXPECT_STREQ(e.what(), "t.rad:2: mesh 'box': option -t needs a number");
    }
}

}  // namespace
}  // namespace dayflux
