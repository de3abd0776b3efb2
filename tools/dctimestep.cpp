// dctimestep: time-step results of the daylight-coefficient (DC x sky) and three-phase
// (V x T x D x sky) methods, or sky-weighted sums of component pictures, as RADIANCE computes them.
#include <tbb/parallel_for.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "matrix/bsdf_xml.h"
#include "matrix/header.h"
#include "matrix/matrices.h"
#include "matrix/products.h"
#include "matrix/rgbe.h"
#include "util/errors.h"
#include "util/strings.h"

namespace dayflux {
namespace {

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(std::string("Usage: ") + prog +
              " [-n nsteps][-o ospec][-i{f|d|a}][-o{f|d|a|c}] DCspec [skyf]\n   or: " + prog +
              " [-n nsteps][-o ospec][-i{f|d|a}][-o{f|d|a|c}] Vspec Tbsdf Dmat.dat [skyf]");
}

// True if s has a %d-like conversion (%d %i %o %x %X with an optional width), as RADIANCE checks.
bool HasNumberFormat(const std::string &s) {
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] != '%') continue;
        if (i + 1 < s.size() && s[i + 1] == '%') {
            ++i;
            continue;
        }
        size_t k = i + 1;
        while (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k]))) ++k;
        if (k < s.size() && std::strchr("dioxX", s[k])) return true;
    }
    return false;
}

// printf(spec, index) for a spec with one integer conversion (checked: no other conversions).
std::string FormatIndex(const std::string &spec, int index) {
    std::string out;
    bool used = false;
    for (size_t i = 0; i < spec.size(); ++i) {
        if (spec[i] != '%') {
            out += spec[i];
            continue;
        }
        if (i + 1 < spec.size() && spec[i + 1] == '%') {
            out += '%';
            ++i;
            continue;
        }
        size_t k = i + 1;
        while (k < spec.size() && std::strchr("-+ #0", spec[k])) ++k;
        while (k < spec.size() && std::isdigit(static_cast<unsigned char>(spec[k]))) ++k;
        if (k >= spec.size() || !std::strchr("dioxX", spec[k]) || used)
            ErrorExit("bad file name specification '" + spec + "': one %d conversion expected");
        std::string conv = spec.substr(i, k - i + 1);
        char buf[64];
        std::snprintf(buf, sizeof buf, conv.c_str(), index);
        out += buf;
        used = true;
        i = k;
    }
    return out;
}

struct Options {
    DataFormat sky_format = DataFormat::Unknown;  // forced (headerless) sky format
    DataFormat out_format = DataFormat::Ascii;
    bool header = true;
    int nsteps = 0;
    std::string ospec;
};

ColumnOperand LoadSky(const std::string &spec, const Options &o) {
    ReadSpec rs;
    rs.header = o.sky_format == DataFormat::Unknown || o.nsteps == 0;
    rs.format = o.sky_format;
    rs.ncols = o.nsteps;
    rs.require_format = o.sky_format == DataFormat::Unknown;
    rs.ncomp = 3;
    MatrixReader reader(spec, rs);
    return ColumnOperand::Read(reader);
}

ColorMatrix LoadColorMatrix(const std::string &spec, int nrows, int ncols) {
    ReadSpec rs;
    rs.require_format = true;
    rs.nrows = nrows;
    rs.ncols = ncols;
    rs.ncomp = 3;
    MatrixReader reader(spec, rs);
    return ReadAll<ColorMatrix>(reader);
}

std::string ResultHeader(const std::string &start, int nrows, int ncols, DataFormat f, int frame) {
    std::string h = start + DateLines();
    if (frame >= 0) h += "FRAME=" + std::to_string(frame) + "\n";
    return h + HeaderFields(nrows, ncols, 3, f);
}

// Sky-weighted sum of component pictures (DCspec with %d), one picture per sky row.
class PictureSum {
  public:
    explicit PictureSum(std::string spec, int npictures)
        : spec_(std::move(spec)), cache_(npictures) {}

    void Write(const std::vector<float> &weights, OutputFile &out) {
        std::vector<float> sum;
        const int n = static_cast<int>(weights.size()) / 3;
        bool first = true;
        for (int i = 0; i < n; ++i) {
            const float *w = &weights[3 * i];
            // Zero weights are skipped, but one picture must be read to know the size.
            if (w[0] == 0 && w[1] == 0 && w[2] == 0 && (!first || i < n - 1)) continue;
            const Picture &p = Get(i);
            if (first) {
                format_ = p.format;
                xres_ = p.xres;
                yres_ = p.yres;
                sum.assign(static_cast<size_t>(xres_) * yres_ * 3, 0.f);
                first = false;
            } else if (p.format != format_ || p.xres != xres_ || p.yres != yres_) {
                ErrorExit("picture '" + FormatIndex(spec_, i) + "' format/size mismatch");
            }
            for (size_t px = 0; px < p.pixels.size(); ++px) {
                const Colr &c = p.pixels[px];
                if (!c[3]) continue;
                float rgb[3];
                FromColr(c, rgb);
                for (int k = 0; k < 3; ++k) sum[3 * px + k] += rgb[k] * w[k];
            }
        }
        std::string text = FormatLine(format_) + "\n" + ResolutionLine(xres_, yres_);
        std::vector<Colr> scan(xres_);
        for (int y = 0; y < yres_; ++y) {
            for (int x = 0; x < xres_; ++x) {
                const float *v = &sum[(static_cast<size_t>(y) * xres_ + x) * 3];
                scan[x] = ToColr(v[0], v[1], v[2]);
            }
            EncodeScanline(scan.data(), xres_, &text);
        }
        out.Write(text);
    }

  private:
    struct Picture {
        DataFormat format = DataFormat::Unknown;
        int xres = 0, yres = 0;
        std::vector<Colr> pixels;
    };
    // Pictures stay in memory (encoded, 4 bytes a pixel) while they fit in a fixed budget.
    const Picture &Get(int i) {
        if (cache_[i]) return *cache_[i];
        auto p = std::make_unique<Picture>();
        const std::string name = FormatIndex(spec_, i);
        auto in = InputSource::Open(name);
        MatrixHeader h = ReadHeader(*in);
        FileLoc loc{name, 0};
        if (!IsPicture(h.format) || !NextIsResolution(*in))
            ErrorExit(&loc, "file is not a picture");
        p->format = h.format;
        ReadResolution(*in, &p->xres, &p->yres);
        p->pixels.resize(static_cast<size_t>(p->xres) * p->yres);
        for (int y = 0; y < p->yres; ++y)
            if (!DecodeScanline(*in, p->pixels.data() + static_cast<size_t>(y) * p->xres, p->xres))
                ErrorExit(&loc, "error reading picture (scanline " + std::to_string(y + 1) + ")");
        const size_t bytes = p->pixels.size() * sizeof(Colr);
        if (cached_bytes_ + bytes > kCacheBytes) {
            scratch_ = std::move(p);
            return *scratch_;
        }
        cached_bytes_ += bytes;
        cache_[i] = std::move(p);
        return *cache_[i];
    }

    static constexpr size_t kCacheBytes = size_t(1) << 30;
    std::string spec_;
    std::vector<std::unique_ptr<Picture>> cache_;
    std::unique_ptr<Picture> scratch_;
    size_t cached_bytes_ = 0;
    DataFormat format_ = DataFormat::RGBE;
    int xres_ = 0, yres_ = 0;
};

int Main(int argc, char **argv) {
    Options o;
    int a = 1;
    for (; a < argc && argv[a][0] == '-'; ++a) {
        const std::string arg = argv[a];
        auto need_value = [&]() -> std::string {
            if (a + 1 >= argc) Usage(argv[0]);
            return argv[++a];
        };
        switch (arg.size() > 1 ? arg[1] : 0) {
            case 'n':
                if (!ParseInt(need_value(), &o.nsteps) || o.nsteps < 0) Usage(argv[0]);
                o.sky_format = o.nsteps ? DataFormat::Ascii : DataFormat::Unknown;
                break;
            case 'h':
                o.header = !o.header;
                break;
            case 'i':
                if (arg == "-if")
                    o.sky_format = DataFormat::Float;
                else if (arg == "-id")
                    o.sky_format = DataFormat::Double;
                else if (arg == "-ia")
                    o.sky_format = DataFormat::Ascii;
                else
                    Usage(argv[0]);
                break;
            case 'o':
                if (arg == "-o")
                    o.ospec = need_value();
                else if (arg == "-of")
                    o.out_format = DataFormat::Float;
                else if (arg == "-od")
                    o.out_format = DataFormat::Double;
                else if (arg == "-oa")
                    o.out_format = DataFormat::Ascii;
                else if (arg == "-oc")
                    o.out_format = DataFormat::RGBE;
                else
                    Usage(argv[0]);
                break;
            default:
                Usage(argv[0]);
        }
    }
    const int nargs = argc - a;
    if (nargs < 1 || nargs > 4) Usage(argv[0]);
    const std::string header_start = HeaderStart(argc, argv);

    // The matrix the first argument multiplies: the sky, or T x (D x sky).
    ColumnOperand right = [&] {
        if (nargs > 2) {
            ColumnOperand sky = LoadSky(nargs > 3 ? argv[a + 3] : "-", o);
            ColorMatrix tmat = IsXmlSpec(argv[a + 1])
                                   ? LoadBsdfMatrix(argv[a + 1], BsdfPart::kTransmission)
                                   : LoadColorMatrix(argv[a + 1], 0, 0);
            ColorMatrix dmat = LoadColorMatrix(argv[a + 2], tmat.cols, sky.Rows());
            ColorMatrix dsky = Multiply(dmat, sky);
            return ColumnOperand::FromMatrix(Multiply(tmat, ColumnOperand::FromMatrix(dsky)));
        }
        return LoadSky(nargs > 1 ? argv[a + 1] : "-", o);
    }();
    const int nsteps = right.Cols();
    std::string ospec = o.ospec;
    if (!ospec.empty() && nsteps == 1 && HasNumberFormat(ospec))
        ospec = FormatIndex(ospec, 1);  // RADIANCE's quirk
    const bool per_step = !ospec.empty() && HasNumberFormat(ospec);

    if (HasNumberFormat(argv[a])) {  // component pictures
        if (o.out_format != DataFormat::RGBE) Warning("changing output type to -oc");
        PictureSum pictures(argv[a], right.Rows());
        std::unique_ptr<OutputFile> out;
        if (!per_step) {
            out = std::make_unique<OutputFile>(ospec);
            out->Write(header_start + DateLines());
        }
        for (int i = 0; i < nsteps; ++i) {
            std::unique_ptr<OutputFile> step;
            if (per_step) {
                step = std::make_unique<OutputFile>(FormatIndex(ospec, i));
                step->Write(header_start + DateLines());
            }
            OutputFile &dst = per_step ? *step : *out;
            if (nsteps > 1) dst.Write("FRAME=" + std::to_string(i) + "\n");
            pictures.Write(right.Column(i), dst);
            if (step) step->Commit();
        }
        if (out) out->Commit();
        return 0;
    }

    ReadSpec vspec;
    vspec.require_format = true;
    vspec.ncols = right.Rows();
    vspec.ncomp = 3;
    MatrixReader left(argv[a], vspec);
    RowFormatter fmt(o.out_format, per_step ? 1 : nsteps, 3, AsciiStyle::kCmatrix);
    if (!per_step) {
        // Rows are streamed, so NROWS comes from the header of the left matrix when it has one.
        ColorMatrix whole;
        if (left.Rows() <= 0) whole = ReadAll<ColorMatrix>(left);
        const int nrows = left.Rows() > 0 ? left.Rows() : whole.rows;
        OutputFile out(ospec);
        if (o.header) out.Write(ResultHeader(header_start, nrows, nsteps, o.out_format, -1));
        if (o.out_format == DataFormat::RGBE) out.Write(ResolutionLine(nsteps, nrows));
        if (left.Rows() > 0)
            StreamProduct(left, right, fmt, out);
        else
            StreamProduct(whole, right, fmt, out);
        out.Commit();
        return 0;
    }
    // One file per time step: hold the left matrix and work through the steps in chunks.
    ColorMatrix vmat = ReadAll<ColorMatrix>(left);
    const int chunk = std::max(
        1, static_cast<int>((size_t(256) << 20) / (sizeof(float) * 3 * std::max(vmat.rows, 1))));
    std::vector<float> res;
    for (int j0 = 0; j0 < nsteps; j0 += chunk) {
        const int w = std::min(chunk, nsteps - j0);
        res.assign(static_cast<size_t>(vmat.rows) * w * 3, 0.f);
        const int block = 18;  // (three of the kernel's groups of six rows)
        tbb::parallel_for(0, (vmat.rows + block - 1) / block, [&](int blk) {
            const int r0 = blk * block, nr = std::min(block, vmat.rows - r0);
            MultiplyRows(vmat.row(r0), nr, vmat.cols, right, j0, j0 + w,
                         res.data() + static_cast<size_t>(r0) * w * 3);
        });
        for (int j = 0; j < w; ++j) {
            OutputFile out(FormatIndex(ospec, j0 + j));
            if (o.header) out.Write(ResultHeader(header_start, vmat.rows, 1, o.out_format, j0 + j));
            if (o.out_format == DataFormat::RGBE) out.Write(ResolutionLine(1, vmat.rows));
            std::string text;
            std::vector<float> column(static_cast<size_t>(vmat.rows) * 3);
            for (int r = 0; r < vmat.rows; ++r) {
                std::memcpy(&column[3 * r], &res[(static_cast<size_t>(r) * w + j) * 3],
                            3 * sizeof(float));
                fmt.Append(&column[3 * r], &text);
            }
            out.Write(text);
            out.Commit();
        }
    }
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
