#include "matrix/bsdf_xml.h"

#include <strings.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <pugixml.hpp>
#include <sstream>
#include <tuple>
#include <utility>

namespace dayflux {

namespace {

AngleBasis MakeBasis(const char *name, std::vector<double> theta, std::vector<int> nphis) {
    return AngleBasis{name, std::move(theta), std::move(nphis)};
}

bool NameIs(const char *a, const char *b) { return strcasecmp(a, b) == 0; }

// RADIANCE's standard (nominal CRT) primaries with an equal-energy white, as color.h defines
// them; the XYZ -> RGB matrix is computed in double and stored in float, as spec_rgb.c does.
struct XyzToRgb {
    float m[3][3];
    XyzToRgb() {
        const double xr = 0.640, yr = 0.330, xg = 0.290, yg = 0.600, xb = 0.150, yb = 0.060;
        const double xw = 1. / 3., yw = 1. / 3.;
        const double CrD = (1. / yw) * (xw * (yg - yb) - yw * (xg - xb) + xg * yb - xb * yg);
        const double CgD = (1. / yw) * (xw * (yb - yr) - yw * (xb - xr) - xr * yb + xb * yr);
        const double CbD = (1. / yw) * (xw * (yr - yg) - yw * (xr - xg) + xr * yg - xg * yr);
        const double v[3][3] = {{(yg - yb - xb * yg + yb * xg) / CrD,
                                 (xb - xg - xb * yg + xg * yb) / CrD, (xg * yb - xb * yg) / CrD},
                                {(yb - yr - yb * xr + yr * xb) / CgD,
                                 (xr - xb - xr * yb + xb * yr) / CgD, (xb * yr - xr * yb) / CgD},
                                {(yr - yg - yr * xg + yg * xr) / CbD,
                                 (xg - xr - xg * yr + xr * yg) / CbD, (xr * yg - xg * yr) / CbD}};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) m[i][j] = static_cast<float>(v[i][j]);
    }
};

// RADIANCE's ccy2rgb(): chromaticity (x, y) and luminance Y to RGB, negatives clipped.
void ChromaToRgb(float cx, float cy, double cie_y, float rgb[3]) {
    static const XyzToRgb mat;
    const double d = static_cast<double>(cx / cy);
    float xyz[3];
    xyz[0] = static_cast<float>(d * cie_y);
    xyz[1] = static_cast<float>(cie_y);
    xyz[2] = static_cast<float>((1. / cy - d - 1.) * cie_y);
    for (int i = 0; i < 3; ++i) {
        float v = mat.m[i][0] * xyz[0] + mat.m[i][1] * xyz[1] + mat.m[i][2] * xyz[2];
        rgb[i] = v < 0 ? 0.f : v;
    }
}

constexpr float kThird = 1.f / 3.f;  // RADIANCE's default (equal-energy) chromaticity

// One scattering matrix of a BSDF, values indexed [out][in] as RADIANCE's SDMat.
struct ScatteringMatrix {
    const AngleBasis *in = nullptr;
    const AngleBasis *out = nullptr;
    std::vector<float> y;     // Visible / CIE-Y
    std::vector<float> x, z;  // CIE-X and CIE-Z when given
    float &Y(int o, int i) { return y[static_cast<size_t>(o) * in->Size() + i]; }
    float Y(int o, int i) const { return y[static_cast<size_t>(o) * in->Size() + i]; }
    bool present() const { return in != nullptr; }
};

struct Component {
    ScatteringMatrix m;
    double lambertian = 0;  // cieY of the extracted diffuse part
    double max_hemi = 0;
    bool loaded = false;  // the file had this component, even if it was dropped as insignificant
};

class BsdfFile {
  public:
    explicit BsdfFile(const std::string &path);
    ColorMatrix Matrix(BsdfPart part);
    KlemsBsdf Data() const;

  private:
    // RADIANCE shares the Lambertian part with a side that has no transmission data of its own.
    std::pair<double, double> TransmissionLambertians() const {
        const double front = tf_.loaded || !tb_.loaded ? tf_.lambertian : tb_.lambertian;
        return {front, tb_.loaded ? tb_.lambertian : front};
    }
    [[noreturn]] void Fail(const std::string &msg, ptrdiff_t offset = -1);
    const AngleBasis *FindBasis(const char *name) const;
    void LoadBlock(pugi::xml_node block, char channel, bool rows_incident);
    void ExtractDiffuse(Component *c);
    void WarnOfDashesInComments() const;
    ColorMatrix Convert(const Component &c, bool reciprocal, double lambertian) const;
    ColorMatrix Lambertian(double lambertian) const;

    std::string path_;
    std::string text_;
    std::vector<AngleBasis> bases_;
    // RADIANCE's sides: XML "Transmission Front" is its back transmission (tb), and so on.
    Component tf_, tb_, rf_, rb_;
};

void BsdfFile::Fail(const std::string &msg, ptrdiff_t offset) {
    FileLoc loc{path_, 0};
    if (offset >= 0 && static_cast<size_t>(offset) <= text_.size()) {
        loc.line = 1;
        for (ptrdiff_t i = 0; i < offset; ++i) loc.line += text_[i] == '\n';
    }
    ErrorExit(&loc, msg);
}

// XML forbids "--" inside a comment. pugixml takes such a file; RADIANCE's reader refuses it
// ("unclosed <!--"), so a file that works here would stop a RADIANCE pipeline: warned, once.
void BsdfFile::WarnOfDashesInComments() const {
    for (size_t at = text_.find("<!--"); at != std::string::npos; at = text_.find("<!--", at)) {
        const size_t end = text_.find("-->", at + 4);
        const size_t dashes = text_.find("--", at + 4);
        if (dashes < end) {
            const FileLoc loc{
                path_,
                1 + static_cast<int>(std::count(
                        text_.begin(), text_.begin() + static_cast<ptrdiff_t>(dashes), '\n'))};
            Warning(&loc,
                    "'--' inside a comment, which XML forbids: RADIANCE's programs refuse "
                    "this file");
            return;
        }
        at = end == std::string::npos ? end : end + 3;
    }
}

const AngleBasis *BsdfFile::FindBasis(const char *name) const {
    for (const AngleBasis &b : bases_)
        if (NameIs(b.name.c_str(), name)) return &b;
    return nullptr;
}

BsdfFile::BsdfFile(const std::string &path) : path_(path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) ErrorExit("cannot open BSDF file '" + path + "'");
    std::stringstream ss;
    ss << f.rdbuf();
    text_ = ss.str();
    pugi::xml_document doc;
    pugi::xml_parse_result res = doc.load_buffer(text_.data(), text_.size());
    if (!res) Fail(std::string("not a valid XML file: ") + res.description(), res.offset);
    WarnOfDashesInComments();
    pugi::xml_node root = doc.child("WindowElement");
    if (!root) Fail("not a BSDF file: the top element is not 'WindowElement'");
    if (pugi::xml_node ft = root.child("FileType"); ft && std::string(ft.text().get()) != "BSDF")
        Fail("wrong FileType '" + std::string(ft.text().get()) + "' (must be 'BSDF')");
    pugi::xml_node layer = root.child("Optical").child("Layer");
    if (!layer) Fail("BSDF has no Optical/Layer element");
    pugi::xml_node def = layer.child("DataDefinition");
    std::string structure = def.child("IncidentDataStructure").text().get();
    if (structure.rfind("TensorTree", 0) == 0)
        Fail("tensor-tree BSDF (" + structure +
             ") is not supported here: only Klems matrix BSDFs "
             "can be used as a matrix");
    bool rows_incident;
    if (NameIs(structure.c_str(), "Rows"))
        rows_incident = true;
    else if (NameIs(structure.c_str(), "Columns"))
        rows_incident = false;
    else if (structure.empty())
        Fail("BSDF is missing DataDefinition/IncidentDataStructure", def ? def.offset_debug() : -1);
    else
        Fail("unsupported IncidentDataStructure '" + structure + "'", def.offset_debug());

    bases_ = KlemsBases();
    for (pugi::xml_node ab = def.child("AngleBasis"); ab; ab = ab.next_sibling("AngleBasis")) {
        std::string name = ab.child("AngleBasisName").text().get();
        if (name.empty()) Fail("AngleBasis without AngleBasisName", ab.offset_debug());
        if (FindBasis(name.c_str())) continue;  // RADIANCE assumes a known name is the same basis
        AngleBasis b;
        b.name = name;
        b.theta.push_back(0);
        for (pugi::xml_node bb = ab.child("AngleBasisBlock"); bb;
             bb = bb.next_sibling("AngleBasisBlock")) {
            double lower = bb.child("ThetaBounds").child("LowerTheta").text().as_double(0);
            double upper = bb.child("ThetaBounds").child("UpperTheta").text().as_double(-1);
            int nphi = bb.child("nPhis").text().as_int(0);
            if (b.nphis.size() && std::fabs(lower - b.theta.back()) > 1e-3)
                Fail("theta bounds disagree in AngleBasis '" + name + "'", bb.offset_debug());
            // Written so that NaN fails too: a polar angle in (previous bound, 90] degrees.
            const bool upper_ok = upper > b.theta.back() && upper <= 90 + 1e-3;
            if (nphi <= 0 || nphi > kMaxBasisSize || (nphi == 1 && b.theta.back() > 1e-6) ||
                !upper_ok)
                Fail("illegal AngleBasisBlock in '" + name + "' (UpperTheta " +
                         std::to_string(upper) + ", nPhis " + std::to_string(nphi) + ")",
                     bb.offset_debug());
            if (b.Size() + nphi > kMaxBasisSize)
                Fail("AngleBasis '" + name + "' has more than " + std::to_string(kMaxBasisSize) +
                         " patches",
                     bb.offset_debug());
            b.theta.push_back(upper);
            b.nphis.push_back(nphi);
        }
        if (b.nphis.empty())
            Fail("AngleBasis '" + name + "' has no AngleBasisBlock", ab.offset_debug());
        bases_.push_back(std::move(b));
    }
    int blocks = 0;
    for (pugi::xml_node wd = layer.child("WavelengthData"); wd;
         wd = wd.next_sibling("WavelengthData")) {
        std::string wl = wd.child("Wavelength").text().get();
        char channel;
        if (NameIs(wl.c_str(), "Visible") || NameIs(wl.c_str(), "CIE-Y"))
            channel = 'Y';
        else if (NameIs(wl.c_str(), "CIE-X"))
            channel = 'X';
        else if (NameIs(wl.c_str(), "CIE-Z"))
            channel = 'Z';
        else
            continue;  // Solar and other bands play no part in daylight matrices
        for (pugi::xml_node b = wd.child("WavelengthDataBlock"); b;
             b = b.next_sibling("WavelengthDataBlock")) {
            LoadBlock(b, channel, rows_incident);
            ++blocks;
        }
    }
    if (!blocks) Fail("BSDF has no Visible WavelengthData blocks");
    for (Component *c : {&rf_, &rb_, &tf_, &tb_}) ExtractDiffuse(c);
}

void BsdfFile::LoadBlock(pugi::xml_node block, char channel, bool rows_incident) {
    std::string dir = block.child("WavelengthDataDirection").text().get();
    Component *c;
    if (NameIs(dir.c_str(), "Transmission Front"))
        c = &tb_;
    else if (NameIs(dir.c_str(), "Transmission Back"))
        c = &tf_;
    else if (NameIs(dir.c_str(), "Reflection Front"))
        c = &rb_;
    else if (NameIs(dir.c_str(), "Reflection Back"))
        c = &rf_;
    else
        Fail("unknown WavelengthDataDirection '" + dir + "'", block.offset_debug());
    const char *cb = block.child("ColumnAngleBasis").text().get();
    const char *rb = block.child("RowAngleBasis").text().get();
    if (!*cb) Fail("missing ColumnAngleBasis", block.offset_debug());
    if (!*rb) Fail("missing RowAngleBasis", block.offset_debug());
    const AngleBasis *in = FindBasis(cb);
    const AngleBasis *out = FindBasis(rb);
    if (!in) Fail(std::string("undefined ColumnAngleBasis '") + cb + "'", block.offset_debug());
    if (!out) Fail(std::string("undefined RowAngleBasis '") + rb + "'", block.offset_debug());
    const int ninc = in->Size(), nout = out->Size();
    pugi::xml_node data = block.child("ScatteringData");
    const char *s = data.text().get();
    if (!*s) Fail("missing ScatteringData", block.offset_debug());
    const size_t count = static_cast<size_t>(ninc) * nout;
    if (std::strlen(s) < count)  // each value takes a character at least: a cheap check first
        Fail("ScatteringData is too short for " + std::to_string(count) + " values",
             data.offset_debug());
    std::vector<float> values(count);
    for (size_t i = 0; i < values.size(); ++i) {
        while (*s && (std::isspace(static_cast<unsigned char>(*s)) || *s == ',')) ++s;
        char *end;
        double v = std::strtod(s, &end);
        if (end == s)
            Fail("ScatteringData has " + std::to_string(i) + " values, expected " +
                     std::to_string(values.size()),
                 data.offset_debug());
        s = end;
        if (v < 0) v = 0;  // RADIANCE allows no negative values
        if (rows_incident) {
            size_t r = i / nout, col = i % nout;  // row = incident direction
            values[col * ninc + r] = static_cast<float>(v);
        } else {
            values[i] = static_cast<float>(v);
        }
    }
    ScatteringMatrix &m = c->m;
    if (m.present() && (m.in != in || m.out != out))
        Fail("BSDF blocks use different angle bases", block.offset_debug());
    m.in = in;
    m.out = out;
    c->loaded = true;
    (channel == 'Y' ? m.y : channel == 'X' ? m.x : m.z) = std::move(values);
}

void BsdfFile::ExtractDiffuse(Component *c) {
    ScatteringMatrix &m = c->m;
    if (!m.present()) return;
    if (m.y.empty()) {  // colour channels without Visible data: nothing RADIANCE would use
        m = ScatteringMatrix();
        return;
    }
    const bool colour = m.x.size() == m.y.size() && m.z.size() == m.y.size();
    if (!colour) m.x.clear(), m.z.clear();
    const int ninc = m.in->Size(), nout = m.out->Size();
    // Largest directional-hemispherical value, to drop insignificant components as RADIANCE does.
    for (int i = 0; i < ninc; ++i) {
        double hemi = 0;
        for (int o = nout; o--;) hemi += m.out->ProjectedSolidAngle(o) * m.Y(o, i);
        c->max_hemi = std::max(c->max_hemi, hemi);
    }
    float ymin = std::numeric_limits<float>::max();
    for (float v : m.y) ymin = std::min(ymin, v);
    if (ymin > .01 / M_PI) {  // a Lambertian part worth separating
        for (float &v : m.y) v -= ymin;
        c->lambertian = M_PI * ymin;
        c->max_hemi -= c->lambertian;
    }
    if (c->max_hemi <= .001) {
        m.x.clear(), m.y.clear(), m.z.clear();
        m.in = m.out = nullptr;
    }
}

ColorMatrix BsdfFile::Convert(const Component &c, bool reciprocal, double lambertian) const {
    const ScatteringMatrix &m = c.m;
    float diffuse[3];
    ChromaToRgb(kThird, kThird, lambertian / M_PI, diffuse);
    const bool colour = !m.x.empty();
    const int nrows = reciprocal ? m.in->Size() : m.out->Size();
    const int ncols = reciprocal ? m.out->Size() : m.in->Size();
    ColorMatrix cm(nrows, ncols, 3);
    cm.dtype = DataFormat::Float;
    int negative = 0, bad_ohm = 0;
    for (int col = 0; col < ncols; ++col) {
        int o_col = col;  // the data column (incident patch) this matrix column reads
        double ohm;
        if (reciprocal) {
            // Incident direction col seen from the other side: an outgoing patch of m.
            double v[3];
            m.in->Centre(col, v);
            o_col = m.out->IndexOf(-v[0], -v[1], v[2]);
            if (o_col < 0) o_col = col;
            ohm = m.out->ProjectedSolidAngle(o_col);
        } else {
            ohm = m.in->ProjectedSolidAngle(col);
        }
        bad_ohm += ohm <= 0;
        for (int row = 0; row < nrows; ++row) {
            int o = row, i = col;
            if (reciprocal) {
                double v[3];
                m.out->Centre(row, v);
                int ri = m.in->IndexOf(-v[0], -v[1], v[2]);
                o = o_col;
                i = ri < 0 ? row : ri;
            }
            const size_t at = static_cast<size_t>(o) * m.in->Size() + i;
            const float f = m.y[at];
            float rgb[3] = {0, 0, 0};
            if (f <= 0 || ohm <= 0) {
                negative += f < -1e-6f;
            } else if (colour) {
                const double sum = static_cast<double>(m.x[at]) + m.y[at] + m.z[at];
                float cx = kThird, cy = kThird;
                if (sum > 0)
                    cx = static_cast<float>(m.x[at] / sum), cy = static_cast<float>(m.y[at] / sum);
                ChromaToRgb(cx, cy, f, rgb);
            } else {
                rgb[0] = rgb[1] = rgb[2] = f;
            }
            float *dst = &cm.at(row, col, 0);
            for (int k = 0; k < 3; ++k)
                dst[k] = static_cast<float>(static_cast<double>(rgb[k] + diffuse[k]) * ohm);
        }
    }
    if (negative || bad_ohm)
        Warning("BTDF has " + std::to_string(negative) + " negatives and " +
                std::to_string(bad_ohm) + " bad incoming solid angles");
    return cm;
}

ColorMatrix BsdfFile::Lambertian(double lambertian) const {
    // As RADIANCE: a purely diffuse component becomes a Klems Full matrix.
    float diffuse[3];
    ChromaToRgb(kThird, kThird, lambertian / M_PI, diffuse);
    const AngleBasis &full = KlemsBases()[0];
    ColorMatrix cm(full.Size(), full.Size(), 3);
    cm.dtype = DataFormat::Float;
    for (int col = 0; col < full.Size(); ++col) {
        double ohm = full.ProjectedSolidAngle(col);
        for (int row = 0; row < full.Size(); ++row)
            for (int k = 0; k < 3; ++k) cm.at(row, col, k) = static_cast<float>(diffuse[k] * ohm);
    }
    return cm;
}

ColorMatrix BsdfFile::Matrix(BsdfPart part) {
    if (part == BsdfPart::kTransmission) {
        if (!tf_.loaded && !tb_.loaded) Fail("BSDF has no transmission data");
        const auto [front, back] = TransmissionLambertians();
        const bool reciprocal = !tb_.m.present();
        const Component &side = reciprocal ? tf_ : tb_;
        const double lambertian = reciprocal ? front : back;
        if (!side.m.present()) return Lambertian(lambertian);
        return Convert(side, reciprocal, lambertian);
    }
    const Component &c = part == BsdfPart::kReflectionFront ? rf_ : rb_;
    if (!c.loaded)
        Fail(std::string("BSDF has no ") + (part == BsdfPart::kReflectionFront ? "front" : "back") +
             " reflection data");
    if (!c.m.present()) return Lambertian(c.lambertian);
    return Convert(c, false, c.lambertian);
}

KlemsBsdf BsdfFile::Data() const {
    const auto component = [](const Component &c) {
        KlemsComponent k;
        if (!c.m.present()) return k;
        k.in = *c.m.in;
        k.out = *c.m.out;
        k.values = c.m.y;
        k.max_hemi = c.max_hemi;
        return k;
    };
    KlemsBsdf d;
    d.rf = component(rf_);
    d.rb = component(rb_);
    d.tf = component(tf_);
    d.tb = component(tb_);
    d.r_lamb_front = rf_.lambertian;
    d.r_lamb_back = rb_.lambertian;
    std::tie(d.t_lamb_front, d.t_lamb_back) = TransmissionLambertians();
    return d;
}

}  // namespace

int AngleBasis::Size() const {
    int n = 0;
    for (int p : nphis) n += p;
    return n;
}

double AngleBasis::ProjectedSolidAngle(int i) const {
    if (i < 0) return -1;
    size_t ring = 0;
    while (ring < nphis.size() && i >= nphis[ring]) i -= nphis[ring++];
    if (ring >= nphis.size()) return -1;
    const double t0 = M_PI / 180. * theta[ring], t1 = M_PI / 180. * theta[ring + 1];
    const double c0 = std::cos(t0), c1 = std::cos(t1);
    return M_PI * (c0 * c0 - c1 * c1) / static_cast<double>(nphis[ring]);
}

int AngleBasis::IndexOf(double x, double y, double z) const {
    if (z < 0 || z > 1.00001) return -1;
    const double pol = 180.0 / M_PI * std::acos(std::min(1.0, z));
    double azi = 180.0 / M_PI * std::atan2(y, x);
    if (azi < 0) azi += 360.0;
    size_t ring = 1;
    for (; ring < theta.size() && theta[ring] <= pol; ++ring) {
    }
    if (ring >= theta.size()) {
        if (pol > theta.back()) return -1;
        ring = theta.size() - 1;
    }
    --ring;
    int ndx = static_cast<int>((1. / 360.) * azi * nphis[ring] + 0.5);
    if (ndx >= nphis[ring]) ndx = 0;
    for (size_t r = 0; r < ring; ++r) ndx += nphis[r];
    return ndx;
}

void AngleBasis::Centre(int i, double v[3]) const {
    size_t ring = 0;
    while (i >= nphis[ring]) i -= nphis[ring++];
    const double c0 = std::cos(M_PI / 180. * theta[ring]),
                 c1 = std::cos(M_PI / 180. * theta[ring + 1]);
    const double cz = std::sqrt(0.5 * (c0 * c0 + c1 * c1));
    const double azi = 2. * M_PI * i / nphis[ring];
    const double sz = std::sqrt(1. - cz * cz);
    v[0] = std::cos(azi) * sz;
    v[1] = std::sin(azi) * sz;
    v[2] = cz;
}

const std::vector<AngleBasis> &KlemsBases() {
    static const std::vector<AngleBasis> bases = {
        MakeBasis("LBNL/Klems Full", {0, 5, 15, 25, 35, 45, 55, 65, 75, 90},
                  {1, 8, 16, 20, 24, 24, 24, 16, 12}),
        MakeBasis("LBNL/Klems Half", {0, 6.5, 19.5, 32.5, 46.5, 61.5, 76.5, 90},
                  {1, 8, 12, 16, 20, 12, 4}),
        MakeBasis("LBNL/Klems Quarter", {0, 9, 27, 46, 66, 90}, {1, 8, 12, 12, 8}),
    };
    return bases;
}

ColorMatrix LoadBsdfMatrix(const std::string &path, BsdfPart part) {
    BsdfFile bsdf(path);
    return bsdf.Matrix(part);
}

KlemsBsdf LoadKlemsBsdf(const std::string &path) { return BsdfFile(path).Data(); }

}  // namespace dayflux
