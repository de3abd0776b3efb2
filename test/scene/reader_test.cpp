#include "scene/reader.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include "test_util.h"

namespace dayflux {
namespace {
namespace fs = std::filesystem;

fs::path Models() { return test::DataDir() / "scene/models"; }

// Reads files as oconv would, with the working folder where the scene's !commands expect it.
Scene ReadIn(const fs::path &dir, const std::vector<std::string> &files) {
    const fs::path cwd = fs::current_path();
    fs::current_path(dir);
    Scene s;
    try {
        s = ReadScene(files);
    } catch (...) {
        fs::current_path(cwd);
        throw;
    }
    fs::current_path(cwd);
    return s;
}

std::string Counts(const Scene &s) {
    std::map<std::string, int> n;
    for (const Primitive &p : s.objects) ++n[p.type];
    std::string out = std::to_string(s.objects.size());
    for (const auto &[t, c] : n) out += " " + t + "=" + std::to_string(c);
    return out;
}

std::map<std::string, std::string> RadianceCounts() {
    std::map<std::string, std::string> m;
    std::ifstream f(test::DataDir() / "scene/counts.txt");
    std::string name, rest;
    while (f >> name && std::getline(f, rest)) m[name] = rest.substr(1);
    return m;
}

TEST(SceneReader, ModelsParseWithRadiancesCounts) {
    auto ref = RadianceCounts();
    const fs::path room = Models() / "room";
    EXPECT_EQ(Counts(ReadIn(room, {"materials.rad", "room.rad", "objects/Glazing.rad",
                                   "skyDomes/skyglow.rad"})),
              ref["room2ph"]);
    EXPECT_EQ(Counts(ReadIn(room, {"materials.rad", "room.rad", "objects/GlazingVmtx.rad"})),
              ref["roomV"]);
    EXPECT_EQ(Counts(ReadIn(room, {"materialBlack.rad", "roomBlack.rad", "materials.rad",
                                   "objects/Glazing.rad"})),
              ref["cds"]);
    EXPECT_EQ(Counts(ReadIn(room, {"skies/suns.rad"})), ref["suns"]);
    std::vector<std::string> open;
    for (const char *f :
         {"ceiling", "floor", "wall", "window_0", "window_1", "window_2", "window_3"})
        open.push_back(std::string(f) + "_openroom.rad");
    Scene openroom;
    SceneReader r(&openroom);
    r.AllowUndefinedModifiers(true);  // its materials live in another file, as for RADIANCE's xform
    for (const auto &f : open) r.ReadFile((Models() / "frads_openroom" / f).string());
    EXPECT_EQ(Counts(openroom), ref["openroom"]);

    test::TempDir tmp;
    ASSERT_EQ(
        test::RunCommand("tar xJf '" + (Models() / "lbnl_office_objects.tar.xz").string() + "'",
                         tmp.path())
            .status,
        0);
    std::vector<std::string> office = {"Objects/materials.mat"};
    for (const char *f :
         {"ceiling", "cubefabric", "cubeframe", "desks", "extwalls", "floor", "ground", "horframe",
          "lower_glass", "overhang", "upper_glass", "walls", "windowframe"})
        office.push_back(std::string("Objects/") + f + ".rad");
    EXPECT_EQ(Counts(ReadIn(tmp.path() / "frads_lbnl_office", office)), ref["lbnl_office"]);
}

TEST(SceneReader, LoadSceneTakesOctreesAndRadFiles) {
    const fs::path room = Models() / "room";
    const fs::path cwd = fs::current_path();
    fs::current_path(room);
    Scene s = LoadScene({"../../room2ph_frozen.oct", "objects/GlazingVmtx.rad"});
    fs::current_path(cwd);
    EXPECT_EQ(s.objects.size(), 29u + 2u);
    EXPECT_EQ(s.objects.back().type, "polygon");
}

TEST(SceneReader, ModifiersResolveToTheLatestDefinition) {
    Scene s;
    SceneReader r(&s);
    r.ReadText(
        "void plastic m 0 0 5 .1 .1 .1 0 0\nm polygon a 0 0 9 0 0 0 1 0 0 0 1 0\n"
        "void metal m 0 0 5 .5 .5 .5 0 0\nm polygon b 0 0 9 0 0 0 1 0 0 0 1 0\n"
        "void alias n m\nn ring c 0 0 8 0 0 0 0 0 1 0 1\n"
        "void brightfunc pat 2 noop . 0 0\npat plastic pm 0 0 5 1 1 1 0 0\ninherit alias pm2 pm\n",
        "t.rad");
    ASSERT_EQ(s.objects.size(), 9u);
    EXPECT_EQ(s.objects[8].modifier, 6);  // inherit: the copy keeps pm's own modifier, pat
    EXPECT_EQ(s.objects[8].modifier_name, "pat");
    EXPECT_EQ(s.objects[1].modifier, 0);
    EXPECT_EQ(s.objects[3].modifier, 2);
    EXPECT_EQ(s.objects[5].modifier, 4);
    EXPECT_EQ(s.objects[4].sargs[0], "m");
}

TEST(SceneReader, CommandsAndXformTransforms) {
    test::TempDir tmp;
    test::WriteFile(tmp.path() / "tri.rad", "m polygon t 0 0 9 1 0 0 0 1 0 0 0 1\n");
    test::WriteFile(tmp.path() / "lamp.rad",
                    "void light bulb 0 0 3 1 1 1\nbulb sphere s 0 0 4 0 0 0 1\n");
    Scene s;
    const fs::path cwd = fs::current_path();
    fs::current_path(tmp.path());
    SceneReader r(&s);
    r.ReadText(
        "void plastic m 0 0 5 .5 .5 .5 0 0\nvoid plastic black 0 0 5 0 0 0 0 0\n"
        "!xform -s 2 -rz 90 -t 1 0 0 tri.rad\n!xform -m black -n w tri.rad\n"
        "!printf 'void glow g 0 0 4 1 1 1 0\\n'\n!xform -n lamp lamp.rad\n",
        "t.rad");
    fs::current_path(cwd);
    ASSERT_EQ(s.objects.size(), 7u);
    // (1,0,0) scaled by 2 -> (2,0,0), turned 90 deg about z -> (0,2,0), moved -> (1,2,0).
    double p[3] = {1, 0, 0}, q[3];
    s.objects[2].xf.Apply(p, q);
    EXPECT_NEAR(q[0], 1, 1e-12);
    EXPECT_NEAR(q[1], 2, 1e-12);
    EXPECT_NEAR(q[2], 0, 1e-12);
    EXPECT_DOUBLE_EQ(s.objects[2].xf.scale, 2);
    EXPECT_EQ(s.objects[3].modifier_name, "black");
    EXPECT_EQ(s.objects[3].modifier, 1);
    EXPECT_EQ(s.objects[3].name, "w.t");
    EXPECT_EQ(s.objects[4].type, "glow");
    // -n names surfaces, not modifiers (as xform does); each xform is kept for oconv's numbers.
    EXPECT_EQ(s.objects[5].name, "bulb");
    EXPECT_EQ(s.objects[6].name, "lamp.s");
    EXPECT_EQ(s.objects[6].modifier, 5);
    ASSERT_TRUE(s.objects[2].xforms && s.objects[6].xforms);
    EXPECT_EQ(s.objects[2].xforms->size(), 1u);
    EXPECT_EQ(s.objects[2].xforms->front().words,
              (std::vector<std::string>{"-i", "1", "-s", "2", "-rz", "90", "-t", "1", "0", "0"}));
    EXPECT_FALSE(s.objects[4].xforms);
}

std::string ErrorOf(const std::string &text) {
    Scene s;
    SceneReader r(&s);
    try {
        r.ReadText(text, "bad.rad");
    } catch (const UserError &e) {
        return e.what();
    }
    return "";
}

TEST(SceneReader, BadInputNamesFileLineAndProblem) {
    EXPECT_EQ(ErrorOf("void plastic m 0 0 5 1 1 1 0 0\nm triangle t 0 0 9 0 0 0 1 0 0 0 1 0\n"),
              "bad.rad:2: unknown type 'triangle' (after modifier 'm')");
    EXPECT_EQ(ErrorOf("void plastic m 0 0 4 1 1 1 0\n"),
              "bad.rad:1: plastic 'm' needs 5 reals (has 0 strings, 4 reals)");
    EXPECT_EQ(ErrorOf("nothere polygon p 0 0 9 0 0 0 1 0 0 0 1 0\n"),
              "bad.rad:1: undefined modifier 'nothere' for polygon 'p'");
    EXPECT_EQ(ErrorOf("void plastic m 0 0 5 1 1 x 0 0\n"),
              "bad.rad:1: plastic 'm': real argument 3 'x' is not a number");
    EXPECT_EQ(ErrorOf("void plastic m 0 0 5 1 1\n"),
              "bad.rad:1: plastic 'm': missing real arguments");
    EXPECT_EQ(ErrorOf("void plastic m 0 1 7 0 5 1 1 1 0 0\n"),
              "bad.rad:1: plastic 'm': integer arguments must be 0");
    EXPECT_EQ(ErrorOf("void plastic m 0 0 5 1 1 1 0 0\nm polygon p 0 0 8 0 0 0 1 0 0 0 1\n"),
              "bad.rad:2: polygon 'p' needs 3n reals with n >= 3 (has 0 strings, 8 reals)");
    EXPECT_NE(ErrorOf("!xform nosuch.rad\n")
                  .find("bad.rad:1: in '!xform nosuch.rad': cannot find 'nosuch.rad' on RAYPATH"),
              std::string::npos);
    EXPECT_EQ(ErrorOf("!false\n"), "bad.rad:1: command '!false' failed");
    // Transforms that would make the geometry vanish or fill space (RADIANCE's xform takes them).
    EXPECT_EQ(ErrorOf("\n!xform -t nan 0 0 x.rad\n"),
              "bad.rad:2: xform: option -t: 'nan' is not a number");
    EXPECT_EQ(ErrorOf("!xform -rz inf x.rad\n"),
              "bad.rad:1: xform: option -rz: 'inf' is not a number");
    EXPECT_EQ(ErrorOf("!xform -s 1e300 x.rad\n"),
              "bad.rad:1: xform: option -s: '1e300' is out of range");
}

}  // namespace
}  // namespace dayflux

namespace dayflux {
namespace {

// "!xform" lines done in-process are read as xform reads its command line (options, transform,
// files); the rest goes to the real xform: -I, arrays, -i with a count, an option out of place.
TEST(SceneReader, XformCommandsAsXformReadsThem) {
    const FileLoc loc{"t.rad", 1};
    XformCommand x;
    ASSERT_TRUE(ParseXformCommand("xform -n a -n b -m m1 -m m2 -e -rz 90 -i 1 -t 1 0 0 f.rad g.rad",
                                  loc, &x));
    EXPECT_EQ(x.name_prefix, "a.b.");
    EXPECT_EQ(x.modifier, "m1");
    EXPECT_EQ(x.files, (std::vector<std::string>{"f.rad", "g.rad"}));
    EXPECT_EQ(x.xf.words,
              (std::vector<std::string>{"-i", "1", "-rz", "90", "-i", "1", "-t", "1", "0", "0"}));
    for (const char *real :
         {"xform -I f.rad", "xform -a 3 -t 1 0 0 f.rad", "xform -i 2 -t 1 0 0 f.rad",
          "xform -s 2 -n late f.rad", "xform f.rad | cat"})
        EXPECT_FALSE(ParseXformCommand(real, loc, &x)) << real;
}

}  // namespace
}  // namespace dayflux
