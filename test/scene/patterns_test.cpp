// Sky patterns of gensky and gendaylit, evaluated with our lib/*.cal, against RADIANCE's rtrace
// on the same sky descriptions (test/data/scene/skies).
#include "scene/patterns.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "scene/reader.h"
#include "test_util.h"

namespace dayflux {
namespace {

class SkyPatterns : public testing::TestWithParam<const char *> {
  protected:
    void SetUp() override { setenv("DAYFLUX_LIB", DAYFLUX_LIB_DIR, 1); }
};

TEST_P(SkyPatterns, MatchRadiancesRtrace) {
    const std::string name = GetParam();
    Scene s = ReadScene({(test::DataDir() / "scene/skies" / (name + ".rad")).string()});
    const int sky = s.FindModifier("skyfunc");
    ASSERT_GE(sky, 0);
    PatternFunction f(s.objects[sky]);
    std::ifstream ref(test::DataDir() / "scene/skies" / (name + "_rtrace.txt"));
    std::string line;
    int n = 0;
    while (std::getline(ref, line)) {
        std::istringstream ss(line);
        double ox, oy, oz, dx, dy, dz, r, g, b;
        ss >> ox >> oy >> oz >> dx >> dy >> dz >> r >> g >> b;
        std::vector<double> ch(27, 0.0);
        ch[0] = dx, ch[1] = dy, ch[2] = dz;
        double rgb[3];
        f.Evaluate(ch, rgb);
        // rtrace prints 7 significant digits.
        EXPECT_NEAR(rgb[0], r, 1e-6 * r + 1e-12)
            << name << " direction " << dx << " " << dy << " " << dz;
        ++n;
    }
    EXPECT_EQ(n, 35);
}

INSTANTIATE_TEST_SUITE_P(GenskyAndGendaylit, SkyPatterns,
                         testing::Values("gensky_clear", "gensky_overcast", "gensky_intermediate",
                                         "gendaylit"));

}  // namespace
}  // namespace dayflux
