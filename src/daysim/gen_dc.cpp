#include "daysim/gen_dc.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "daysim/patches.h"
#include "daysim/rtrace_dc.h"
#include "daysim/suns.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/strings.h"

namespace dayflux {

namespace {

std::string Fixed(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%f", v);
    return buf;
}

// rtrace_dc's command line as gen_dc builds it (getOptionString), without the scene.
std::vector<std::string> RtraceArgs(const DaysimRtraceSettings &s, const GenDcOptions &g) {
    std::vector<std::string> a = {"rtrace_dc-gpu",
                                  "-h",
                                  "-" + s.irradiance_switch,
                                  "-oc",
                                  "-aa",
                                  Fixed(s.aa),
                                  "-ab",
                                  std::to_string(s.ab),
                                  "-ad",
                                  std::to_string(s.ad),
                                  "-ar",
                                  std::to_string(s.ar),
                                  "-as",
                                  std::to_string(s.as),
                                  "-dj",
                                  Fixed(s.dj),
                                  "-dr",
                                  std::to_string(s.dr),
                                  "-ds",
                                  Fixed(s.ds),
                                  "-lr",
                                  std::to_string(s.lr),
                                  "-lw",
                                  Fixed(s.lw),
                                  "-ss",
                                  "1.000000",
                                  "-st",
                                  Fixed(s.st)};
    for (const std::string &w : SplitWords(s.additional)) a.push_back(w);
    a.insert(a.end(), {"-L", "1000.000000"});
    a.insert(a.end(), g.engine_args.begin(), g.engine_args.end());
    return a;
}

class GenDc {
  public:
    GenDc(const DaysimProject &p, const GenDcOptions &g) : p_(p), g_(g) {
        p.Require("sensor_file", !p.sensor_file.empty());
        p.Require("shading", !p.variants.empty());
        sensors_ = p.Path(p.sensor_file) + g.extension;
        sensor_count_ = CountSensors(sensors_);
        if (!p.sensor_units.empty() && p.sensor_units.size() != sensor_count_)
            ErrorExit(&p.sensor_units_loc, "sensor_file_unit gives " +
                                               std::to_string(p.sensor_units.size()) +
                                               " units for the " + std::to_string(sensor_count_) +
                                               " sensors of " + sensors_);
        std::filesystem::create_directories(p.tmp_directory.empty() ? "." : p.tmp_directory);
    }

    void Run() {
        std::string sky, suns;
        if (g_.diffuse) sky = WriteSky();
        if (g_.direct) {
            p_.Require("latitude", p_.latitude.has_value());
            suns = WriteSuns();
        }
        // DAYSIM's simple blinds model (shading 0) has one .dc for both settings.
        for (const DaysimVariant &v : p_.variants) {
            if (g_.diffuse) Trace(v, sky, DiffuseArgs(), Temp(v, "dif"));
            if (g_.direct) Trace(v, suns, DirectArgs(), Temp(v, "dir"));
            if (g_.merge) Merge(v);
        }
    }

  private:
    std::string Temp(const DaysimVariant &v, const char *kind) const {
        return (std::filesystem::path(p_.tmp_directory) / (v.name + "." + kind + ".dc")).string();
    }

    std::string WriteSky() const {
        const std::string f = (std::filesystem::path(p_.tmp_directory) / "skyPatches.rad").string();
        OutputFile out(f);
        out.Write(
            "void glow sky\n0\n0\n4  1000 1000 1000  0\n\nsky source himmel\n0\n0\n4  0 0 1  "
            "360\n\n");
        out.Commit();
        return f;
    }

    std::string WriteSuns() {
        table_ = DaysimDirectSuns(*p_.latitude * (M_PI / 180.));
        const std::string f =
            p_.direct_radiance_file.empty()
                ? (std::filesystem::path(p_.tmp_directory) / "direct_radiance_file.tmp.rad")
                      .string()
                : p_.Path(p_.direct_radiance_file);
        OutputFile out(f);
        out.Write(DaysimSunScene(table_));
        out.Commit();
        return f;
    }

    std::vector<std::string> DiffuseArgs() const {
        std::vector<std::string> a = RtraceArgs(p_.diffuse, g_);
        a.insert(a.end(), {"-N", std::to_string(kDaysimDiffusePatches), "-Dd"});
        return a;
    }
    std::vector<std::string> DirectArgs() const {
        std::vector<std::string> a = RtraceArgs(p_.direct, g_);
        a.insert(a.end(), {"-N", std::to_string(std::max<size_t>(1, table_.suns.size())), "-Dm",
                           "-dt", "0.000000"});
        return a;
    }

    // One rtrace_dc run into `dc`: two comment lines (what ran), then a line per sensor.
    void Trace(const DaysimVariant &v, const std::string &sources, std::vector<std::string> args,
               const std::string &dc) {
        args.push_back(sources);
        for (const std::string &f : p_.material_files) args.push_back(p_.Path(f));
        if (!v.scene.empty()) args.push_back(p_.Path(v.scene));
        for (const std::string &f : p_.geometry_files) args.push_back(p_.Path(f));
        std::string command;
        for (const std::string &w : args) command += (command.empty() ? "" : " ") + w;
        command += " < " + sensors_ + " > " + dc;
        if (g_.show_commands) std::printf("gen_dc: %s\n", command.c_str());
        std::vector<std::string> header;
        RtraceDcOptions o = ParseRtraceDcOptions(args, &header);
        o.sensor_units = SensorUnits();
        OutputFile out(dc);
        out.Write("# dayflux rtrace_dc-gpu\n# " + command + "\n");
        const size_t rows = RunRtraceDc(o, header, sensors_, &out);
        if (rows != sensor_count_)
            ErrorExit(sensors_ + ": " + std::to_string(rows) +
                      " sensors traced, but the file has " + std::to_string(sensor_count_) +
                      " lines");
        out.Commit();
    }

    // rtrace_dc's -U: irradiance (1) for illuminance and irradiance sensors, radiance (0) for
    // luminance and radiance ones; none where every sensor is of the first kind.
    std::vector<int> SensorUnits() const {
        std::vector<int> units;
        bool mixed = false;
        for (int u : p_.sensor_units) {
            units.push_back(u == 0 || u == 2 ? 1 : 0);
            mixed |= units.back() == 0;
        }
        return mixed ? units : std::vector<int>{};
    }

    void Merge(const DaysimVariant &v) const {
        const std::string dif = Temp(v, "dif"), dir = Temp(v, "dir");
        const std::unique_ptr<InputSource> dif_in = InputSource::Open(dif),
                                           dir_in = InputSource::Open(dir);
        OutputFile out(p_.Path(v.dc) + g_.extension);
        char latitude[64];
        std::snprintf(latitude, sizeof latitude, "%.2f", p_.latitude.value_or(0));
        out.Write("# merged daylight coefficients from " + dif + " and " + dir +
                  ".\n# latitude: " + latitude + "\n");
        std::string a, b;
        size_t rows = 0;
        int dif_line = 0;
        while (dir_in->ReadLine(&a)) {
            ++dif_line;
            if (!dif_in->ReadLine(&b))
                ErrorExit(dif + ": fewer lines than " + dir + " (run gen_dc -dif again)");
            const FileLoc line_loc{dif, dif_line};
            if (!a.empty() && a[0] == '#') {
                if (b.empty() || b[0] != '#')
                    ErrorExit(&line_loc, "a comment line expected beside " + dir + "'s");
                out.Write("# direct:\t" + a.substr(1) + "\n# diffuse:\t" + b.substr(1) + "\n");
                continue;
            }
            if (SplitWords(b).size() != kDaysimDiffusePatches)
                ErrorExit(&line_loc, "a line of 148 diffuse coefficients expected");
            out.Write(b + a + "\n");
            ++rows;
        }
        if (dif_in->ReadLine(&b)) ErrorExit(dif + ": more lines than " + dir);
        if (rows != sensor_count_)
            ErrorExit(dir + ": " + std::to_string(rows) + " lines of coefficients for " +
                      std::to_string(sensor_count_) + " sensors");
        out.Commit();
    }

    const DaysimProject &p_;
    const GenDcOptions &g_;
    std::string sensors_;
    size_t sensor_count_ = 0;
    DaysimSunTable table_;
};

}  // namespace

void RunGenDc(const DaysimProject &project, const GenDcOptions &options) {
    GenDc(project, options).Run();
}

}  // namespace dayflux
