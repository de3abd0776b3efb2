// fcplan: false-colour floor plans of sensor values, such as an hour's illuminance from a
// dctimestep result or a metric from dcmetrics' CSV, as a PNG with a scale and, for other
// tools, as RADIANCE HDR and OpenEXR.
#include <cmath>
#include <string>
#include <vector>

#include "image/plans.h"
#include "matrix/reader.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/options.h"
#include "util/photometry.h"
#include "util/strings.h"

namespace dayflux {
namespace {

[[noreturn]] void Usage(const char *prog) {
    ErrorExit(
        std::string("Usage: ") + prog +
        " -i sensors.pts [-c column][-t title][-u unit][-min v][-s max][-w white_at][-b boundary]"
        "[-px pixels][-o plan.png][-hdr plan.hdr][-exr plan.exr] {values.mtx | "
        "metrics.csv}");
}

struct Options {
    std::string points, column, png, hdr, exr, values;
    PlanStyle style;
    bool scale_given = false;
};

double Number(int argc, char **argv, int *i) { return OptionNumber(argc, argv, i, Usage); }

Options ParseOptions(int argc, char **argv) {
    Options o;
    int i = 1;
    for (; i < argc && argv[i][0] == '-' && argv[i][1]; ++i) {
        const std::string a = argv[i];
        const bool has_arg = i + 1 < argc;
        if (a == "-i" && has_arg) {
            o.points = argv[++i];
        } else if (a == "-c" && has_arg) {
            o.column = argv[++i];
        } else if (a == "-t" && has_arg) {
            o.style.title = argv[++i];
        } else if (a == "-u" && has_arg) {
            o.style.unit = argv[++i];
        } else if (a == "-min") {
            o.style.min = Number(argc, argv, &i);
        } else if (a == "-s") {
            o.style.max = Number(argc, argv, &i);
            o.scale_given = true;
        } else if (a == "-w") {
            o.style.white_at = Number(argc, argv, &i);
        } else if (a == "-b") {
            o.style.boundary = Number(argc, argv, &i);
        } else if (a == "-px") {
            const double px = Number(argc, argv, &i);
            if (!(px >= 1 && px <= 256)) ErrorExit("-px: pixels per cell must be 1 to 256");
            o.style.pixels_per_cell = static_cast<int>(px);
        } else if (a == "-o" && has_arg) {
            o.png = argv[++i];
        } else if (a == "-hdr" && has_arg) {
            o.hdr = argv[++i];
        } else if (a == "-exr" && has_arg) {
            o.exr = argv[++i];
        } else {
            Usage(argv[0]);
        }
    }
    if (i + 1 != argc || o.points.empty()) Usage(argv[0]);
    if (o.png.empty() && o.hdr.empty() && o.exr.empty())
        ErrorExit("no output: give -o, -hdr or -exr");
    o.values = argv[i];
    return o;
}

bool EndsWith(const std::string &s, const std::string &tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::vector<std::string> SplitCsv(const std::string &line) {
    std::vector<std::string> f;
    size_t start = 0;
    while (true) {
        const size_t comma = line.find(',', start);
        f.push_back(
            line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (!f.empty() && !f.back().empty() && f.back().back() == '\r') f.back().pop_back();
    return f;
}

// One column of a CSV with a header line, by name.
std::vector<double> ReadCsvColumn(const std::string &path, const std::string &name) {
    if (name.empty()) ErrorExit(path + ": name the column to draw with -c");
    auto in = InputSource::Open(path);
    std::string line;
    if (!in->ReadLine(&line)) ErrorExit(path + ": empty file");
    const std::vector<std::string> head = SplitCsv(line);
    size_t col = 0;
    while (col < head.size() && head[col] != name) ++col;
    if (col == head.size()) ErrorExit(in->Name() + ":1: no column named '" + name + "'");
    std::vector<double> v;
    while (true) {
        const FileLoc loc = in->Loc();
        if (!in->ReadLine(&line)) break;
        if (line.empty()) continue;
        const std::vector<std::string> f = SplitCsv(line);
        double x;
        if (col >= f.size() || !ParseNumber(f[col], &x))
            ErrorExit(&loc, "no number in column '" + name + "'");
        v.push_back(x);
    }
    in->Close();
    return v;
}

// One column (a time step) of a RADIANCE matrix with a row per sensor, as illuminance.
std::vector<double> ReadMatrixColumn(const std::string &spec, const std::string &column) {
    MatrixReader r(spec);
    int col = 0;
    if (!column.empty() && (!ParseInt(column, &col) || col < 0 || col >= r.Cols()))
        ErrorExit(r.Name() + ": -c " + column + ": columns are numbered 0 to " +
                  std::to_string(r.Cols() - 1));
    if (r.Comps() != 1 && r.Comps() != 3)
        ErrorExit(r.Name() + ": NCOMP=" + std::to_string(r.Comps()) + ": expected 1 or 3");
    std::vector<double> row(static_cast<size_t>(r.Cols()) * r.Comps()), v;
    while (r.Rows() == 0 || static_cast<int>(v.size()) < r.Rows()) {
        if (!r.ReadRow(row.data())) break;
        const double *e = &row[static_cast<size_t>(col) * r.Comps()];
        v.push_back(r.Comps() == 1 ? e[0] : IlluminanceFromRgb(e));
    }
    r.Finish();
    return v;
}

int Main(int argc, char **argv) {
    Options o = ParseOptions(argc, argv);
    const std::vector<SensorPoint> points = ReadSensorPoints(o.points);
    const bool csv = EndsWith(o.values, ".csv");
    const std::vector<double> values =
        csv ? ReadCsvColumn(o.values, o.column) : ReadMatrixColumn(o.values, o.column);
    if (values.size() != points.size())
        ErrorExit(o.values + ": " + std::to_string(values.size()) + " values for " +
                  std::to_string(points.size()) + " sensors in " + o.points);
    for (size_t i = 0; i < values.size(); ++i)
        if (!std::isfinite(values[i]))
            ErrorExit(o.values + ": the value of sensor " + std::to_string(i + 1) +
                      " is not a finite number");
    if (!o.scale_given) {  // the largest value, rounded up to a round number
        double top = 0;
        for (double v : values) top = std::max(top, v);
        const double step = top > 0 ? std::pow(10., std::floor(std::log10(top))) : 1.;
        o.style.max = std::max(o.style.min + step, std::ceil(top / step) * step);
    }
    if (!(o.style.max > o.style.min)) ErrorExit("-s: the scale's top must be above -min");
    const PlanRaster plan = RasterizePlan(points, values);
    if (!o.png.empty()) WritePlanPng(o.png, plan, o.style);
    // Illuminance from a matrix goes into pictures as RADIANCE keeps it (W/m2, read back as lux
    // with the usual 179 by pvalue and falsecolor); metrics from a CSV go in as they are.
    const double scale = csv ? 1. : 1. / kLuminousEfficacy;
    if (!o.hdr.empty()) WritePlanHdr(o.hdr, plan, scale, o.style.pixels_per_cell);
    if (!o.exr.empty()) WritePlanExr(o.exr, plan, scale, o.style.pixels_per_cell);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
