// The estimator core's view of a Klems matrix (raytrace/core/klems.inl on the packed data):
// values against the three-phase T matrix, and sampled directions against the matrix's own
// distribution.
#include "raytrace/klems.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <sstream>

#include "raytrace/core/sampling.h"
#include "raytrace/packing.h"
#include "test_util.h"

namespace dayflux {
namespace {

// A Klems Half BSDF file with one transmission block ("Transmission Front", RADIANCE's back
// transmission tb) whose BSDF(out o, in i) is value(o, i).
std::string TransmissionXml(const std::function<double(int, int)> &value) {
    const int n = 73;
    std::ostringstream x;
    x.precision(17);
    x << "<?xml version=\"1.0\"?>\n<WindowElement><FileType>BSDF</FileType><Optical><Layer>\n"
      << "<DataDefinition><IncidentDataStructure>Columns</IncidentDataStructure>"
      << "</DataDefinition>\n<WavelengthData><Wavelength>Visible</Wavelength>"
      << "<WavelengthDataBlock><WavelengthDataDirection>Transmission Front"
      << "</WavelengthDataDirection><ColumnAngleBasis>LBNL/Klems Half</ColumnAngleBasis>"
      << "<RowAngleBasis>LBNL/Klems Half</RowAngleBasis><ScatteringData>";
    for (int o = 0; o < n; ++o)
        for (int i = 0; i < n; ++i) x << value(o, i) << (o * n + i + 1 < n * n ? ", " : "");
    x << "</ScatteringData></WavelengthDataBlock></WavelengthData></Layer></Optical>"
      << "</WindowElement>\n";
    return x.str();
}

double Uneven(int o, int i) { return 0.05 + 0.02 * ((o * 7 + i * 3) % 11) + (o == i ? 2. : 0.); }

using namespace core;

// The core's Klems functions (raytrace/core/klems.inl) over one BSDF's packed data, in double.
struct KlemsData {
    explicit KlemsData(const KlemsScattering &k) {
        PackKlemsData(k, &table);
        klems = table.data();
    }
    std::vector<float> table;
    const float *klems = nullptr;
    [[maybe_unused]] static constexpr int b = 0;  // the BSDF's offset (klems.inl)
#define DAYFLUX_BSDF 1
#include "raytrace/core/klems.inl"
#undef DAYFLUX_BSDF
};

core::real3 Vec(const double v[3]) { return core::real3(v[0], v[1], v[2]); }

class KlemsTest : public testing::Test {
  protected:
    void SetUp() override {
        test::WriteFile(tmp.path() / "t.xml", TransmissionXml(Uneven));
        path = (tmp.path() / "t.xml").string();
    }
    test::TempDir tmp;
    std::string path;
    const AngleBasis &half = KlemsBases()[1];
};

// The core's patch lookup and projected solid angles, from the packed tables, agree with the
// basis's own.
TEST(KlemsBasisTable, AgreesWithAngleBasis) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    for (const AngleBasis &b : KlemsBases()) {
        KlemsBsdf bsdf;
        bsdf.tf.in = bsdf.tf.out = b;
        bsdf.tf.values.assign(static_cast<size_t>(b.Size()) * b.Size(), 1.);
        KlemsData k{KlemsScattering(bsdf)};
        const int q = k.PartT(0, true);
        ASSERT_GE(q, 0) << b.name;
        for (int n = 0; n < 100000; ++n) {
            double w[3] = {u(rng), u(rng), u(rng)};
            const double l = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
            for (double &x : w) x /= l;
            // tf's outgoing basis is on the back: its front-out frame mirrors z.
            const int index = k.PartIndex(q, core::real3(w[0], w[1], -w[2]), false);
            ASSERT_EQ(index, b.IndexOf(w[0], w[1], w[2])) << b.name;
            if (index >= 0) {
                ASSERT_FLOAT_EQ(k.PartSolidAngle(q, index, false), b.ProjectedSolidAngle(index));
            }
        }
    }
}

// Light from the back (z < 0, direction -centre(c)) leaving the front (centre(r)): the value
// times the incident patch's projected solid angle is the T matrix of dctimestep and rmtxop.
TEST_F(KlemsTest, ValuesAreTheTransmissionMatrix) {
    const KlemsScattering scattering(LoadKlemsBsdf(path));
    KlemsData k(scattering);
    const ColorMatrix t = LoadBsdfMatrix(path, BsdfPart::kTransmission);
    EXPECT_GT(scattering.TransmissionLambertian(false), 0.04);  // the minimum was taken out ...
    EXPECT_EQ(scattering.TransmissionLambertian(true),
              scattering.TransmissionLambertian(false));  // ... and shared
    for (int r = 0; r < half.Size(); ++r)
        for (int c = 0; c < half.Size(); ++c) {
            double in[3], out[3];
            half.Centre(c, in);
            for (double &x : in) x = -x;
            half.Centre(r, out);
            const double expect = t.at(r, c, 0) / half.ProjectedSolidAngle(c);
            ASSERT_NEAR(k.KlemsEval(0, Vec(in), Vec(out)), expect, 1e-6 * expect) << r << " " << c;
            ASSERT_NEAR(k.KlemsEval(0, Vec(out), Vec(in)), expect, 1e-6 * expect);  // reciprocity
        }
    // no reflection data, no Lambertian reflection
    EXPECT_EQ(k.KlemsEval(0, core::real3(0, 0, -1), core::real3(0, 0, -1)), 0.);
}

// Directions drawn for a view direction land in each patch in proportion to BSDF x projected
// solid angle (chi-square over the 73 patches), on the side opposite the view, and carry the
// hemispherical total; from the front, the back-side data serve by reciprocity.
TEST_F(KlemsTest, SamplesFollowTheMatrix) {
    const KlemsScattering scattering(LoadKlemsBsdf(path));
    KlemsData k(scattering);
    ASSERT_EQ(k.PartT(0, true), k.PartT(0, false)) << "tb serves both sides";
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    const double lambertian = scattering.TransmissionLambertian(true) / M_PI;
    for (int side = 0; side < 2; ++side) {
        const int q = k.PartT(0, side == 1);
        const int fixed = 17;
        double view[3];
        half.Centre(fixed, view);
        if (side == 0) view[2] = -view[2];  // from the back: tb's own incident side
        std::vector<double> expect(half.Size());
        double total = 0;
        for (int j = 0; j < half.Size(); ++j) {
            double other[3];
            half.Centre(j, other);
            if (side == 1)
                for (double &x : other) x = -x;  // tb's incident basis (bi): mirrored through 0
            const double f = side == 0 ? k.KlemsEval(0, Vec(view), Vec(other))
                                       : k.KlemsEval(0, Vec(other), Vec(view));
            expect[j] = (f - lambertian) * half.ProjectedSolidAngle(j);
            total += expect[j];
        }
        EXPECT_NEAR(k.SpecularHemi(0, Vec(view), true), total, 1e-5 * total);
        const int n = 200000;
        std::vector<int> count(half.Size(), 0);
        for (int s = 0; s < n; ++s) {
            core::real3 out;
            const double v = k.KlemsSample(q, Vec(view), u(rng), u(rng), u(rng), out);
            ASSERT_NEAR(v, total, 1e-5 * total);
            ASSERT_LT(out.z * view[2], 0) << "transmission leaves on the other side";
            const double sign = side == 0 ? 1 : -1;
            const int j = half.IndexOf(sign * out.x, sign * out.y, sign * out.z);
            ASSERT_GE(j, 0);
            ++count[j];
        }
        double chi2 = 0;
        int cells = 0;
        for (int j = 0; j < half.Size(); ++j) {
            const double e = n * expect[j] / total;
            if (e < 1e-4) {  // entries at the minimum: nothing left once the Lambertian is out
                EXPECT_EQ(count[j], 0) << j;
                continue;
            }
            chi2 += (count[j] - e) * (count[j] - e) / e;
            ++cells;
        }
        EXPECT_GT(cells, 60);
        EXPECT_LT(chi2, 130.) << "at most 72 degrees of freedom: p < 1e-4 above 130";
    }
}

}  // namespace
}  // namespace dayflux
