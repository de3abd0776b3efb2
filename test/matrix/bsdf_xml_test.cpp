#include "matrix/bsdf_xml.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <tuple>

#include "test_util.h"

namespace dayflux {
namespace {

TEST(KlemsBases, SizesAndProjectedSolidAnglesSumToPi) {
    const int sizes[] = {145, 73, 41};
    for (size_t b = 0; b < 3; ++b) {
        const AngleBasis &basis = KlemsBases()[b];
        ASSERT_EQ(basis.Size(), sizes[b]) << basis.name;
        double sum = 0;
        for (int i = 0; i < basis.Size(); ++i) sum += basis.ProjectedSolidAngle(i);
        EXPECT_NEAR(sum, M_PI, 1e-12) << basis.name;
    }
}

TEST(KlemsBases, CentresMapBackToTheirPatches) {
    for (const AngleBasis &basis : KlemsBases())
        for (int i = 0; i < basis.Size(); ++i) {
            double v[3];
            basis.Centre(i, v);
            EXPECT_EQ(basis.IndexOf(v[0], v[1], v[2]), i) << basis.name;
        }
    // Patch 1 of Klems Full is centred on azimuth 0 (ring 5-15 degrees).
    const AngleBasis &full = KlemsBases()[0];
    const double t = 10 * M_PI / 180;
    EXPECT_EQ(full.IndexOf(std::sin(t), 0, std::cos(t)), 1);
    EXPECT_EQ(full.IndexOf(0, 0, -1), -1);
}

std::string SyntheticBsdf(const char *basis, int n, const std::string &structure, double t_front,
                          double t_back, double r_value) {
    std::ostringstream x;
    x.precision(17);
    x << "<?xml version=\"1.0\"?>\n<WindowElement>\n<FileType>BSDF</FileType>\n<Optical><Layer>\n"
      << "<DataDefinition><IncidentDataStructure>" << structure
      << "</IncidentDataStructure></DataDefinition>\n";
    auto block = [&](const char *dir, double value) {
        x << "<WavelengthData><Wavelength>Visible</Wavelength><WavelengthDataBlock>"
          << "<WavelengthDataDirection>" << dir << "</WavelengthDataDirection>"
          << "<ColumnAngleBasis>" << basis << "</ColumnAngleBasis><RowAngleBasis>" << basis
          << "</RowAngleBasis>"
          << "<ScatteringData>";
        for (int i = 0; i < n * n; ++i)
            x << value * (1 + (i % n == i / n)) << (i + 1 < n * n ? ", " : "");
        x << "</ScatteringData></WavelengthDataBlock></WavelengthData>\n";
    };
    if (t_front >= 0) block("Transmission Front", t_front);
    if (t_back >= 0) block("Transmission Back", t_back);
    block("Reflection Front", r_value);
    x << "</Layer></Optical></WindowElement>\n";
    return x.str();
}

// Element (out r, in c) = BSDF(r, c) x projected solid angle of incident patch c. With BSDF =
// v (1 + delta_rc), a uniform incident radiance L gives outgoing radiance L (v pi + v ohm_r).
TEST(BsdfMatrix, TransmissionIsBsdfTimesIncidentProjectedSolidAngle) {
    test::TempDir tmp;
    const double v = 0.2 / M_PI;
    test::WriteFile(tmp.path() / "t.xml",
                    SyntheticBsdf("LBNL/Klems Half", 73, "Columns", v, -1, 0.1 / M_PI));
    ColorMatrix t = LoadBsdfMatrix((tmp.path() / "t.xml").string(), BsdfPart::kTransmission);
    const AngleBasis &half = KlemsBases()[1];
    ASSERT_EQ(t.rows, 73);
    ASSERT_EQ(t.cols, 73);
    for (int r = 0; r < 73; ++r) {
        double sum = 0;
        for (int c = 0; c < 73; ++c) {
            sum += t.at(r, c, 1);
            const double expect = v * (1 + (r == c)) * half.ProjectedSolidAngle(c);
            // Float storage, the diffuse part taken out and added back through RGB: a few
            // roundings.
            ASSERT_NEAR(t.at(r, c, 0), expect, 5e-7 * expect);
            // Grey stays grey to float rounding (RADIANCE's XYZ-to-RGB matrix is not exactly 1).
            ASSERT_NEAR(t.at(r, c, 0), t.at(r, c, 2), 1e-6 * expect);
        }
        EXPECT_NEAR(sum, v * M_PI + v * half.ProjectedSolidAngle(r), 1e-6);
    }
}

TEST(BsdfMatrix, RowsAndColumnsStructuresAreTransposes) {
    test::TempDir tmp;
    // Asymmetric data: value depends on the position in the list.
    auto make = [&](const std::string &structure, bool transpose) {
        std::ostringstream x;
        x << "<WindowElement><Optical><Layer><DataDefinition><IncidentDataStructure>" << structure
          << "</IncidentDataStructure></DataDefinition><WavelengthData><Wavelength>Visible</"
             "Wavelength>"
          << "<WavelengthDataBlock><WavelengthDataDirection>Transmission "
             "Front</WavelengthDataDirection>"
          << "<ColumnAngleBasis>LBNL/Klems Quarter</ColumnAngleBasis><RowAngleBasis>LBNL/Klems "
             "Quarter</RowAngleBasis>"
          << "<ScatteringData>";
        for (int i = 0; i < 41 * 41; ++i) {
            int a = i / 41, b = i % 41;
            x << 0.001 * (transpose ? b * 41 + a : i) << ' ';
        }
        x << "</ScatteringData></WavelengthDataBlock></WavelengthData></Layer></Optical></"
             "WindowElement>";
        return x.str();
    };
    test::WriteFile(tmp.path() / "c.xml", make("Columns", false));
    test::WriteFile(tmp.path() / "r.xml", make("Rows", true));
    ColorMatrix c = LoadBsdfMatrix((tmp.path() / "c.xml").string(), BsdfPart::kTransmission);
    ColorMatrix r = LoadBsdfMatrix((tmp.path() / "r.xml").string(), BsdfPart::kTransmission);
    EXPECT_EQ(c.data, r.data);
}

// RADIANCE uses the XML "Transmission Back" through reciprocity when "Front" is missing:
// for Klems bases that mirrors both directions through the axis, so a symmetric BSDF is unchanged.
TEST(BsdfMatrix, ReciprocityWhenOnlyTransmissionBackIsGiven) {
    test::TempDir tmp;
    const double v = 0.3 / M_PI;
    test::WriteFile(tmp.path() / "f.xml",
                    SyntheticBsdf("LBNL/Klems Full", 145, "Columns", v, -1, 0.1));
    test::WriteFile(tmp.path() / "b.xml",
                    SyntheticBsdf("LBNL/Klems Full", 145, "Columns", -1, v, 0.1));
    ColorMatrix f = LoadBsdfMatrix((tmp.path() / "f.xml").string(), BsdfPart::kTransmission);
    ColorMatrix b = LoadBsdfMatrix((tmp.path() / "b.xml").string(), BsdfPart::kTransmission);
    ASSERT_EQ(f.data.size(), b.data.size());
    for (size_t i = 0; i < f.data.size(); ++i) EXPECT_NEAR(f.data[i], b.data[i], 1e-7) << i;
}

// A purely Lambertian BSDF is separated into its diffuse part and, as in RADIANCE, comes back as a
// Klems Full matrix whatever its basis; every row then sums to the diffuse transmittance.
TEST(BsdfMatrix, LambertianBsdfConservesTransmittance) {
    test::TempDir tmp;
    std::string xml = SyntheticBsdf("LBNL/Klems Half", 73, "Columns", -1, -1, 0.1);
    const std::string block =
        "<WavelengthData><Wavelength>Visible</"
        "Wavelength><WavelengthDataBlock><WavelengthDataDirection>"
        "Transmission Front</WavelengthDataDirection><ColumnAngleBasis>LBNL/Klems "
        "Half</ColumnAngleBasis>"
        "<RowAngleBasis>LBNL/Klems Half</RowAngleBasis><ScatteringData>";
    std::string values;
    for (int i = 0; i < 73 * 73; ++i) values += std::to_string(0.5 / M_PI) + " ";
    xml.insert(xml.find("</Layer>"),
               block + values + "</ScatteringData></WavelengthDataBlock></WavelengthData>");
    test::WriteFile(tmp.path() / "l.xml", xml);
    ColorMatrix t = LoadBsdfMatrix((tmp.path() / "l.xml").string(), BsdfPart::kTransmission);
    ASSERT_EQ(t.rows, 145);
    for (int r = 0; r < 145; ++r) {
        double sum = 0;
        for (int c = 0; c < 145; ++c) sum += t.at(r, c, 1);
        EXPECT_NEAR(sum, 0.5, 1e-5);
    }
}

std::string LoadError(const std::string &xml, BsdfPart part = BsdfPart::kTransmission) {
    test::TempDir tmp;
    test::WriteFile(tmp.path() / "e.xml", xml);
    try {
        LoadBsdfMatrix((tmp.path() / "e.xml").string(), part);
    } catch (const UserError &e) {
        std::string s = e.what();
        return s.substr(s.find("e.xml"));
    }
    return "";
}

TEST(BsdfMatrix, BadFilesGetMessages) {
    EXPECT_EQ(LoadError("<WindowElement>\n<Optical>\n</Layer>"),
              "e.xml:3: not a valid XML file: Start-end tags mismatch");
    EXPECT_EQ(LoadError("<Other/>"),
              "e.xml: not a BSDF file: the top element is not 'WindowElement'");
    EXPECT_EQ(
        LoadError(
            "<WindowElement><Optical><Layer><DataDefinition><IncidentDataStructure>TensorTree3"
            "</IncidentDataStructure></DataDefinition></Layer></Optical></WindowElement>"),
        "e.xml: tensor-tree BSDF (TensorTree3) is not supported here: only Klems matrix BSDFs can "
        "be used "
        "as a matrix");
    std::string xml = SyntheticBsdf("LBNL/Klems Quarter", 41, "Columns", 0.1, -1, 0.1);
    const size_t end = xml.find("</ScatteringData>");
    const size_t last = xml.rfind(", ", end);
    xml.erase(last, end - last);  // one value short
    EXPECT_NE(LoadError(xml).find("ScatteringData has 1680 values, expected 1681"),
              std::string::npos);
    EXPECT_NE(LoadError(SyntheticBsdf("My/Basis", 41, "Columns", 0.1, -1, 0.1))
                  .find("undefined ColumnAngleBasis 'My/Basis'"),
              std::string::npos);
}

// A basis of the file's own whose second ring ends at `upper` degrees with `nphis` patches.
std::string OwnBasisBsdf(const std::string &upper, const std::string &nphis) {
    std::string xml = SyntheticBsdf("Mine", 1 + 8, "Columns", 0.1, -1, 0.1);
    const std::string basis =
        "<AngleBasis><AngleBasisName>Mine</AngleBasisName><AngleBasisBlock><nPhis>1</nPhis>"
        "<ThetaBounds><LowerTheta>0</LowerTheta><UpperTheta>5</UpperTheta></ThetaBounds>"
        "</AngleBasisBlock><AngleBasisBlock><nPhis>" +
        nphis + "</nPhis><ThetaBounds><LowerTheta>5</LowerTheta><UpperTheta>" + upper +
        "</UpperTheta></ThetaBounds></AngleBasisBlock></AngleBasis>";
    xml.insert(xml.find("</DataDefinition>"), basis);
    return xml;
}

// Angles outside the hemisphere (or not numbers) and patch counts beyond memory are refused
// with their values, instead of giving an all-zero matrix or a failed allocation.
TEST(BsdfMatrix, ImpossibleBasesGetMessages) {
    EXPECT_EQ(LoadError(OwnBasisBsdf("90", "8")), "");
    for (const auto &[upper, nphis, said] :
         {std::tuple{"nan", "8", "(UpperTheta nan, nPhis 8)"},
          std::tuple{"400", "8", "(UpperTheta 400.000000, nPhis 8)"},
          std::tuple{"90", "2000000000", "(UpperTheta 90.000000, nPhis 2000000000)"}}) {
        const std::string error = LoadError(OwnBasisBsdf(upper, nphis));
        EXPECT_NE(error.find("illegal AngleBasisBlock in 'Mine' " + std::string(said)),
                  std::string::npos)
            << error;
    }
}

}  // namespace
}  // namespace dayflux
