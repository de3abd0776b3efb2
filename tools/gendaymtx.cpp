// gendaymtx: sky matrices (one row per patch, ground first; one column per time step) from
// weather files, with RADIANCE's Perez sky, sun spreading, options and output layout.
#include <malloc.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "matrix/header.h"
#include "sky/perez.h"
#include "sky/weather.h"
#include "util/errors.h"
#include "util/options.h"
#include "util/pipeline.h"
#include "util/strings.h"

namespace dayflux {
namespace {

constexpr double kEfficacy = 179.;

double Rad(double deg) { return deg * (M_PI / 180.); }

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(std::string("Usage: ") + prog +
              " [-v][-h][-A][-d|-s|-n][-u][-D file [-M modfile]][-r deg][-m N][-g r g b][-c r g "
              "b][-o{f|d}]"
              "[-O{0|1}][-max_steps N] [tape.wea]");
}

struct Step {
    SkyStep sky;
    bool dark = true;  // all-zero column
};

struct Options {
    SkyOptions sky;
    bool header = true, verbose = false, sun_hours_only = false;
    int average = 0;  // 1: -A, -1: no matrix (-n, -D -)
    char format = 'a';
    std::string suns_file, mods_file, weather = "-";
    // Ours: every time step is held until the rows are written (about 450 bytes each; RADIANCE
    // holds its whole matrix), so a weather file with more is refused, not memory exhausted.
    long max_steps = 5000000;
};

double Number(int argc, char **argv, int *i) { return OptionNumber(argc, argv, i, Usage); }

Options ParseOptions(int argc, char **argv) {
    Options o;
    int i = 1;
    auto colour = [&](float c[3]) {
        for (int k = 0; k < 3; ++k) c[k] = static_cast<float>(Number(argc, argv, &i));
    };
    auto direct_only = [&] {
        for (int k = 0; k < 3; ++k) o.sky.sky_color[k] = o.sky.ground_reflectance[k] = 0;
    };
    for (; i < argc && argv[i][0] == '-'; ++i) {
        const std::string a = argv[i];
        if (a == "-max_steps") {
            const double n = Number(argc, argv, &i);
            if (!(n >= 1 && n <= 1e9) || n != std::floor(n))
                ErrorExit("-max_steps needs a whole number from 1 to 1000000000");
            o.max_steps = static_cast<long>(n);
            continue;
        }
        switch (a.size() > 1 ? a[1] : 0) {
            case 'g':
                colour(o.sky.ground_reflectance);
                break;
            case 'v':
                o.verbose = true;
                break;
            case 'h':
                o.header = false;
                break;
            case 'o':
                if (a != "-of" && a != "-od" && a != "-oa") Usage(argv[0]);
                o.format = a[2];
                break;
            case 'O':
                if (a != "-O0" && a != "-O1") Usage(argv[0]);
                o.sky.solar_radiance = a[2] == '1';
                break;
            case 'm': {
                double mf = Number(argc, argv, &i);
                if (mf < 1 || mf != std::floor(mf) || mf > 64)
                    ErrorExit("-m needs a whole number from 1 to 64");
                o.sky.mf = static_cast<int>(mf);
                break;
            }
            case 'c':
                colour(o.sky.sky_color);
                break;
            case 'D':
                if (i + 1 >= argc) Usage(argv[0]);
                o.suns_file = argv[++i];
                if (o.suns_file != "-") break;  // a file: the matrix still goes to stdout
                o.average = -1;                 // suns on stdout: no matrix, direct only
                o.sky.mf = 1;
                direct_only();
                break;
            case 'n':
                o.average = -1;
                o.sky.mf = 1;
                direct_only();
                break;
            case 'd':
                direct_only();
                break;
            case 'M':
                if (i + 1 >= argc) Usage(argv[0]);
                o.mods_file = argv[++i];
                break;
            case 's':
                for (float &c : o.sky.sun_color) c = 0;
                break;
            case 'u':
                o.sun_hours_only = true;
                break;
            case 'r':
                if (a != "-r" && a != "-rz") Usage(argv[0]);
                o.sky.rotation_deg = Number(argc, argv, &i);
                break;
            case '5': {
                o.sky.sun_patches = 1;
                double half = M_PI / 360. * Number(argc, argv, &i);
                if (half <= 0) ErrorExit("missing solar disk size argument for '-5' option");
                o.sky.fixed_sun_solid_angle = half * half * M_PI;
                break;
            }
            case 'A':
                o.average = 1;
                break;
            default:
                Usage(argv[0]);
        }
    }
    if (i < argc - 1) Usage(argv[0]);
    if (i == argc - 1) o.weather = argv[i];
    return o;
}

// Appends RADIANCE's sun description for one time step (gendaymtx -D).
void AppendSun(std::string *out, int id, double radiance, const float sun_color[3], double altitude,
               double azimuth) {
    char buf[512];
    double v[3];
    v[1] = std::cos(altitude);
    v[0] = v[1] * std::sin(azimuth);
    v[1] *= std::cos(azimuth);
    v[2] = std::sin(altitude);
    std::snprintf(buf, sizeof buf,
                  "\nvoid light solar%d\n0\n0\n3 %.3e %.3e %.3e\n\nsolar%d source sun%d\n0\n0\n4 "
                  "%.6f %.6f %.6f %.4f\n",
                  id, radiance * sun_color[0], radiance * sun_color[1], radiance * sun_color[2], id,
                  id, v[0], v[1], v[2], kSunAngleDeg);
    *out += buf;
}

int Main(int argc, char **argv) {
    Options o = ParseOptions(argc, argv);
    if (!o.mods_file.empty() && o.suns_file.empty()) Warning("-M output will be empty without -D");
    WeatherReader weather(o.weather);
    const WeatherHeader &wh = weather.Header();
    SkyModel model(o.sky);
    const SkyPatchBasis &patches = model.Patches();
    const int npatch = patches.Size();
    if (o.verbose) {
        std::fprintf(stderr, "%s: reading weather tape '%s'\n", ProgramName().c_str(),
                     weather.Name().c_str());
        std::fprintf(stderr, "%s: location '%s'\n", ProgramName().c_str(), wh.place.c_str());
        std::fprintf(stderr, "%s: (lat,long)=(%.1f,%.1f) degrees north, west\n",
                     ProgramName().c_str(), wh.latitude, wh.longitude);
        if (o.average >= 0)
            std::fprintf(stderr, "%s: %d sky patches\n", ProgramName().c_str(), npatch);
    }
    Site site{Rad(wh.latitude), Rad(wh.longitude), Rad(wh.time_zone)};
    const WeatherUnits units = static_cast<WeatherUnits>(wh.units);

    // Pass 1: sun positions in order (leap days shift the days after them), then the
    // patch-independent sky quantities of every step, in parallel.
    struct Pending {
        WeatherRecord rec;
        int julian;
        double altitude, azimuth;
        bool sun_in_sky;
    };
    std::vector<Pending> pending;
    SunTrack sun(site);
    WeatherRecord rec;
    while (weather.Next(&rec)) {
        const SunTrack::Position pos = sun.Next(rec.month, rec.day, rec.hour);
        if (o.sun_hours_only && !pos.in_sky) continue;
        if (static_cast<long>(pending.size()) == o.max_steps) {
            const FileLoc loc{weather.Name(), rec.line};
            ErrorExit(&loc, "more than " + std::to_string(o.max_steps) +
                                " time steps (-max_steps): split the weather file, or raise "
                                "-max_steps where memory allows (about 450 bytes a step)");
        }
        Pending p{rec, pos.day_of_year, pos.altitude, pos.azimuth + M_PI - Rad(o.sky.rotation_deg),
                  pos.in_sky};
        pending.push_back(p);
    }
    if (pending.empty()) ErrorExit(weather.Name() + ": no valid time steps on input");
    const int nsteps = static_cast<int>(pending.size());
    std::vector<Step> steps(nsteps);
    tbb::parallel_for(0, nsteps, [&](int i) {
        const Pending &p = pending[i];
        if (p.rec.dir + p.rec.dif <= 1e-4) return;  // effectively night
        steps[i].dark = false;
        steps[i].sky = model.Prepare(p.rec.dir, p.rec.dif, units, p.altitude, p.azimuth, p.julian,
                                     o.average >= 0);
    });
    // Units 2 at a sun on the horizon: the capped direct normal values, counted (SkyStep).
    int capped = 0, first_capped = -1;
    for (int i = 0; i < nsteps; ++i)
        if (steps[i].sky.direct_capped && capped++ == 0) first_capped = i;
    if (capped > 0) {
        const Pending &p = pending[first_capped];
        const FileLoc loc{weather.Name(), p.rec.line};
        char buf[320];
        std::snprintf(
            buf, sizeof buf,
            "%g W/m2 direct on the horizontal at a solar altitude of %.3g degrees is "
            "more than the sun gives normal to it, and made the sky NaN (as RADIANCE's): taken as "
            "%g W/m2 (%d time step%s)",
            p.rec.dir, p.altitude * 180 / M_PI, kMostIrradiance, capped, capped == 1 ? "" : "s");
        Warning(&loc, buf);
    }
    std::string suns, mods;
    for (int i = 0; i < nsteps; ++i) {
        const Pending &p = pending[i];
        const bool bright_limit =
            p.rec.dir > (units == WeatherUnits::kPhotometric ? 20. * kEfficacy : 20.);
        if (!steps[i].dark && !p.sun_in_sky && bright_limit) {
            char buf[128];
            std::snprintf(buf, sizeof buf, "unusually bright at %.1f on %d-%d", p.rec.hour,
                          p.rec.month, p.rec.day);
            Warning(buf);
        }
        if (!o.suns_file.empty() && p.sun_in_sky) {
            const int id = 24 * 60 * (p.julian - 1) + static_cast<int>(p.rec.hour * 60. + .5);
            const double srad = Rad(kSunAngleDeg / 2.);
            const double radiance =
                steps[i].dark ? 0 : steps[i].sky.dir_illum / (kEfficacy * M_PI * srad * srad);
            AppendSun(&suns, id, radiance, o.sky.sun_color, p.altitude, p.azimuth);
            mods += "solar" + std::to_string(id) + "\n";
        }
    }
    if (!o.suns_file.empty()) {
        OutputFile sf(o.suns_file);
        sf.Write(suns);
        sf.Commit();
        if (!o.mods_file.empty()) {
            OutputFile mf(o.mods_file);
            mf.Write(mods);
            mf.Commit();
        }
    } else if (!o.mods_file.empty()) {
        OutputFile mf(o.mods_file);
        mf.Commit();
    }
    if (o.average < 0) return 0;
    std::vector<Pending>().swap(pending);  // memory for the rows

    // Sun contributions, indexed by patch.
    std::vector<std::vector<std::pair<int, float>>> sun_at(npatch);
    for (int i = 0; i < nsteps; ++i)
        for (const SunPatch &s : steps[i].sky.sun) sun_at[s.patch].emplace_back(i, s.value);

    const bool average = o.average > 0;
    const int ncols = average ? 1 : nsteps;
    OutputFile out("-");
    if (o.header) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "LATLONG= %.8f %.8f\n", site.latitude * (180. / M_PI),
                      -site.longitude * (180. / M_PI));
        const DataFormat f = o.format == 'f'   ? DataFormat::Float
                             : o.format == 'd' ? DataFormat::Double
                                               : DataFormat::Ascii;
        out.Write(HeaderStart(argc, argv) + buf + HeaderFields(npatch, ncols, 3, f));
    }
    if (o.verbose)
        std::fprintf(stderr, "%s: writing %smatrix with %d time steps...\n", ProgramName().c_str(),
                     o.format == 'a' ? "" : "binary ", ncols);

    // Pass 2: patch rows, computed and formatted in parallel blocks, written in order.
    const int block =
        std::max(1, static_cast<int>((4u << 20) / (12u * static_cast<unsigned>(nsteps) + 1)));
    struct Block {
        int p0, p1;
        std::string text;
    };
    std::vector<const SkyStep *> step_ptrs(nsteps);
    for (int i = 0; i < nsteps; ++i) step_ptrs[i] = steps[i].dark ? nullptr : &steps[i].sky;
    const SkyModel::StepArrays step_arrays = model.Arrays(step_ptrs);
    int next = 0;
    OrderedPipeline<Block>(
        [&]() -> std::unique_ptr<Block> {
            if (next >= npatch) return nullptr;
            auto b = std::make_unique<Block>(Block{next, std::min(npatch, next + block), {}});
            next = b->p1;
            return b;
        },
        [&](Block &b) {
            // Reserve the block's output at once: growing it would copy it over and over.
            const size_t bytes_per_value = o.format == 'a' ? 10 : o.format == 'f' ? 4 : 8;
            b.text.reserve(static_cast<size_t>(b.p1 - b.p0) * (3 * ncols + 1) * bytes_per_value);
            std::vector<float> v(3 * static_cast<size_t>(nsteps));
            std::vector<char> line;
            SkyModel::RowWork work;  // this block's row factors
            int cached_row = -1;
            for (int p = b.p0; p < b.p1; ++p) {
                if (p == 0) {
                    for (int i = 0; i < nsteps; ++i)
                        for (int k = 0; k < 3; ++k)
                            v[3 * i + k] = steps[i].dark ? 0.f : steps[i].sky.ground[k];
                } else {
                    if (model.RowOf(p) != cached_row) {
                        cached_row = model.RowOf(p);
                        model.RowFactors(step_ptrs, step_arrays, p, &work);
                    }
                    model.PatchValues(step_arrays, p, &work, v.data());
                    for (const auto &[i, val] : sun_at[p])
                        for (int k = 0; k < 3; ++k) v[3 * i + k] += val * o.sky.sun_color[k];
                }
                const float *row = v.data();
                float avg[3];
                if (average) {
                    avg[0] = avg[1] = avg[2] = 0.f;
                    for (int i = 0; i < nsteps; ++i)
                        for (int k = 0; k < 3; ++k) avg[k] += v[3 * i + k];
                    if (nsteps > 1)
                        for (float &a : avg) a = static_cast<float>(a * (1. / nsteps));
                    row = avg;
                }
                if (o.format == 'a') {
                    // Into a buffer of a row's worst case, then onto the block's text at once.
                    line.resize(static_cast<size_t>(ncols) * 3 * 32 + 2);
                    char *q = line.data();
                    for (int j = 0; j < ncols; ++j) {
                        for (int k = 0; k < 3; ++k) {
                            q = FormatGeneral(q, row[3 * j + k], 3);
                            *q++ = k < 2 ? ' ' : '\n';
                        }
                    }
                    if (ncols > 1) *q++ = '\n';
                    b.text.append(line.data(), q);
                } else if (o.format == 'f') {
                    b.text.append(reinterpret_cast<const char *>(row), sizeof(float) * 3 * ncols);
                } else {
                    for (int j = 0; j < 3 * ncols; ++j) {
                        double d = row[j];
                        b.text.append(reinterpret_cast<const char *>(&d), sizeof d);
                    }
                }
            }
        },
        [&](Block &b) { out.Write(b.text); });
    out.Commit();
    if (o.verbose) std::fprintf(stderr, "%s: done.\n", ProgramName().c_str());
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) {
    // Keep freed blocks in the heap: blocks of output are allocated again and again, and fresh
    // pages from the kernel cost more than the work done in them.
    mallopt(M_MMAP_THRESHOLD, 256 << 20);
    mallopt(M_TRIM_THRESHOLD, 512 << 20);
    return dayflux::RunTool(argc, argv, dayflux::Main);
}
