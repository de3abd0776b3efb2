#include "scene/octree.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scene/oconv.h"
#include "scene/reader.h"
#include "test_util.h"

namespace dayflux {
namespace {
namespace fs = std::filesystem;

// Runs f with the working folder set to the tutorial room, where oconv ran.
template <class F>
auto InRoom(F f) {
    const fs::path cwd = fs::current_path();
    fs::current_path(test::DataDir() / "scene/models/room");
    struct Restore {
        fs::path p;
        ~Restore() { fs::current_path(p); }
    } restore{cwd};
    return f();
}

void ExpectSameObjects(const Scene &a, const Scene &b) {
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (size_t i = 0; i < a.objects.size(); ++i) {
        const Primitive &p = a.objects[i], &q = b.objects[i];
        EXPECT_EQ(p.type, q.type) << i;
        EXPECT_EQ(p.name, q.name) << i;
        EXPECT_EQ(p.modifier, q.modifier) << p.name;
        EXPECT_EQ(p.modifier_name, q.modifier_name) << p.name;
        EXPECT_EQ(p.sargs, q.sargs) << p.name;
        ASSERT_EQ(p.fargs.size(), q.fargs.size()) << p.name;
        // Frozen octrees store reals with a 31-bit mantissa.
        for (size_t k = 0; k < p.fargs.size(); ++k)
            EXPECT_NEAR(p.fargs[k], q.fargs[k], 1e-9 * std::max(1.0, std::fabs(q.fargs[k])))
                << p.name;
    }
}

TEST(Octree, FrozenOctreeHoldsTheSameObjectsAsItsSources) {
    InRoom([] {
        Scene rad =
            ReadScene({"materials.rad", "room.rad", "objects/Glazing.rad", "skyDomes/skyglow.rad"});
        Scene oct;
        OctreeInfo info = ReadOctree("../../room2ph_frozen.oct", &oct);
        EXPECT_TRUE(info.files.empty());
        EXPECT_GT(info.cube_size, 6.0);
        EXPECT_NE(info.header.find("oconv -f materials.rad"), std::string::npos);
        ExpectSameObjects(oct, rad);
        Scene black = ReadScene(
            {"materialBlack.rad", "roomBlack.rad", "materials.rad", "objects/Glazing.rad"});
        Scene cds;
        ReadOctree("../../cds_frozen.oct", &cds);
        ExpectSameObjects(cds, black);
        return 0;
    });
}

TEST(Octree, UnfrozenOctreeReadsItsSceneFiles) {
    InRoom([] {
        Scene oct;
        OctreeInfo info = ReadOctree("../../room2ph.oct", &oct);
        EXPECT_EQ(info.files.size(), 4u);
        ExpectSameObjects(oct, ReadScene({"materials.rad", "room.rad", "objects/Glazing.rad",
                                          "skyDomes/skyglow.rad"}));
        EXPECT_TRUE(IsOctreeFile("../../room2ph.oct"));
        EXPECT_FALSE(IsOctreeFile("room.rad"));
        return 0;
    });
}

// Our oconv remakes RADIANCE 5.4's octrees of the tutorial room byte for byte: the LBNL recipes'
// four (frozen and not) and the two-phase ones. (test/data/oconv holds RADIANCE's quirks:
// transforms, instances, meshes, -i, -n, -r, -b, standard input; RadiancePrograms compares them.)
TEST(Octree, OconvRemakesRadiancesOctreesOfTheTutorialRoom) {
    InRoom([] {
        const struct {
            const char *octree;
            std::vector<std::string> files;
            bool frozen;
        } cases[] = {
            {"../../../recipes/octrees/roomDC.oct",
             {"materials.rad", "room.rad", "objects/Glazing.rad"},
             false},
            {"../../../recipes/octrees/room3ph.oct", {"materials.rad", "room.rad"}, true},
            {"../../../recipes/octrees/room3phDirect.oct",
             {"materialBlack.rad", "roomBlack.rad"},
             true},
            {"../../../recipes/octrees/roomDCBlack.oct",
             {"materialBlack.rad", "roomBlack.rad", "materials.rad", "objects/Glazing.rad"},
             false},
            {"../../room2ph_frozen.oct",
             {"materials.rad", "room.rad", "objects/Glazing.rad", "skyDomes/skyglow.rad"},
             true},
            {"../../cds_frozen.oct",
             {"materialBlack.rad", "roomBlack.rad", "materials.rad", "objects/Glazing.rad"},
             true},
        };
        for (const auto &c : cases) {
            SCOPED_TRACE(c.octree);
            OconvOptions o;
            o.frozen = c.frozen;
            std::string command = c.frozen ? "oconv -f" : "oconv";
            for (const std::string &f : c.files) command += " " + f;
            const std::string made = MakeOctree(c.files, o, command + "\n");
            EXPECT_TRUE(made == test::ReadFile(c.octree)) << "made " << made.size() << " bytes";
        }
        return 0;
    });
}

// Adding to an octree (-i) keeps its objects and tree and sorts the new ones into it; what is
// read back is the first scene followed by the second.
TEST(Octree, OconvAddsToAnOctree) {
    InRoom([] {
        test::TempDir tmp;
        const std::string first = (tmp.path() / "first.oct").string();
        OconvOptions o;
        o.frozen = true;
        test::WriteFile(first, MakeOctree({"materials.rad", "room.rad"}, o, "oconv -f\n"));
        o.input_octree = first;
        o.frozen = false;  // a frozen input keeps the result frozen (with a warning)
        o.warnings = false;
        const std::string both = (tmp.path() / "both.oct").string();
        test::WriteFile(both, MakeOctree({"objects/Glazing.rad"}, o, "oconv -i first.oct\n"));
        Scene read;
        const OctreeInfo info = ReadOctree(both, &read);
        EXPECT_TRUE(info.files.empty());
        EXPECT_NE(info.header.find("oconv -f\noconv -i first.oct\n"), std::string::npos);
        ExpectSameObjects(read, ReadScene({"materials.rad", "room.rad", "objects/Glazing.rad"}));
        return 0;
    });
}

std::string ErrorOf(const std::string &path) {
    try {
        Scene s;
        ReadOctree(path, &s);
    } catch (const UserError &e) {
        std::string m = e.what();
        return m.substr(m.rfind('/') + 1);
    }
    return "";
}

TEST(Octree, BadOctreesGetMessages) {
    test::TempDir tmp;
    std::string full = test::ReadFile(test::DataDir() / "scene/room2ph_frozen.oct");
    test::WriteFile(tmp.path() / "short.oct", full.substr(0, full.size() - 100));
    EXPECT_EQ(ErrorOf((tmp.path() / "short.oct").string()), "short.oct: truncated octree");
    test::WriteFile(tmp.path() / "text.oct", "#?RADIANCE\nFORMAT=ascii\n\n");
    EXPECT_EQ(ErrorOf((tmp.path() / "text.oct").string()),
              "text.oct: not a RADIANCE octree (FORMAT=ascii)");
    test::WriteFile(tmp.path() / "nameless.oct", "#?RADIANCE\noconv\n\n");
    EXPECT_EQ(ErrorOf((tmp.path() / "nameless.oct").string()),
              "nameless.oct: not a RADIANCE octree (no FORMAT=Radiance_octree in header)");
    // Cut inside its header, an octree is still taken for one (not read as an empty scene).
    test::WriteFile(tmp.path() / "ten.oct", full.substr(0, 10));
    EXPECT_TRUE(IsOctreeFile((tmp.path() / "ten.oct").string()));
    EXPECT_EQ(ErrorOf((tmp.path() / "ten.oct").string()),
              "ten.oct: truncated octree (in its header)");
    // A tree of 100000 levels (each a node of eight children): refused, not a stack overflow.
    std::string deep = "#?RADIANCE\nFORMAT=Radiance_octree\n\n";
    const int magic = 4 * 8 + 251 + 4;  // RADIANCE's, for 4-byte object numbers
    deep += std::string{static_cast<char>(magic >> 8), static_cast<char>(magic & 0xff)};
    deep += std::string(
                "0\0"
                "0\0"
                "0\0"
                "1\0",
                8) +
            std::string(1, '\0');                              // cube, no files
    deep += std::string(4, '\0') + std::string(100000, '\2');  // 0 objects, tree
    test::WriteFile(tmp.path() / "deep.oct", deep);
    EXPECT_EQ(ErrorOf((tmp.path() / "deep.oct").string()),
              "deep.oct: damaged octree (tree deeper than 128 levels)");
    EXPECT_EQ(ErrorOf((tmp.path() / "none.oct").string()), "none.oct': No such file or directory");
}

}  // namespace
}  // namespace dayflux
