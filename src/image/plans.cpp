#include "image/plans.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStdIO.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "matrix/rgbe.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/strings.h"

namespace dayflux {

std::vector<SensorPoint> ReadSensorPoints(const std::string &path) {
    auto in = InputSource::Open(path);
    std::vector<SensorPoint> pts;
    std::string line;
    while (true) {
        const FileLoc loc = in->Loc();
        if (!in->ReadLine(&line)) break;
        double v[6];
        int n = 0;
        size_t pos = 0;
        while (n < 6) {
            pos = line.find_first_not_of(" \t\r", pos);
            if (pos == std::string::npos) break;
            const size_t end = line.find_first_of(" \t\r", pos);
            const std::string word = line.substr(pos, end - pos);
            if (!ParseNumber(word, &v[n]) || !std::isfinite(v[n]))
                ErrorExit(&loc, "'" + word + "' in a sensor point is not a number");
            ++n;
            pos = end;
        }
        if (n == 0) continue;
        if (n != 6) ErrorExit(&loc, "a sensor point needs 6 numbers (x y z dx dy dz)");
        pts.push_back(SensorPoint{v[0], v[1], v[2], loc});
    }
    in->Close();
    if (pts.empty()) ErrorExit(in->Name() + ": no sensor points");
    return pts;
}

namespace {

// The smallest gap between distinct coordinates (distinct: more than 1e-6 of the extent apart).
double SmallestSpacing(std::vector<double> c, double *lo, double *hi) {
    std::sort(c.begin(), c.end());
    *lo = c.front();
    *hi = c.back();
    const double eps = 1e-6 * std::max(1., *hi - *lo);
    double best = 0;
    for (size_t i = 1; i < c.size(); ++i) {
        const double d = c[i] - c[i - 1];
        if (d > eps && (best == 0 || d < best)) best = d;
    }
    return best;
}

}  // namespace

PlanRaster RasterizePlan(const std::vector<SensorPoint> &points,
                         const std::vector<double> &values) {
    CHECK(points.size() == values.size() && !points.empty());
    std::vector<double> xs, ys;
    for (const SensorPoint &p : points) xs.push_back(p.x), ys.push_back(p.y);
    double x0, x1, y0, y1;
    PlanRaster r;
    r.cell_x = SmallestSpacing(xs, &x0, &x1);
    r.cell_y = SmallestSpacing(ys, &y0, &y1);
    if (r.cell_x == 0) r.cell_x = r.cell_y;
    if (r.cell_y == 0) r.cell_y = r.cell_x;
    if (r.cell_x == 0) r.cell_x = r.cell_y = 1;  // a single sensor
    const double w = std::floor((x1 - x0) / r.cell_x + 0.5 + 1e-6) + 1,
                 h = std::floor((y1 - y0) / r.cell_y + 0.5 + 1e-6) + 1;
    if (w > 4096 || h > 4096)
        ErrorExit("the sensors do not lie on a grid that fits a picture (" +
                  std::to_string(static_cast<long>(w)) + " x " +
                  std::to_string(static_cast<long>(h)) + " cells)");
    r.width = static_cast<int>(w);
    r.height = static_cast<int>(h);
    r.values.assign(static_cast<size_t>(r.width) * r.height, 0.f);
    r.filled.assign(r.values.size(), 0);
    std::vector<size_t> owner(r.values.size());
    for (size_t i = 0; i < points.size(); ++i) {
        // Offices side by side can sit on exact half cells: round those one way, whatever the
        // rounding error of each coordinate.
        const int col = static_cast<int>(std::floor((points[i].x - x0) / r.cell_x + 0.5 + 1e-6));
        const int row =
            r.height - 1 - static_cast<int>(std::floor((points[i].y - y0) / r.cell_y + 0.5 + 1e-6));
        const size_t k = static_cast<size_t>(row) * r.width + col;
        if (r.filled[k])
            ErrorExit(&points[i].loc,
                      "this sensor and the one at " + points[owner[k]].loc.ToString() +
                          " fall in one cell of the plan: the points are not on a grid");
        owner[k] = i;
        r.filled[k] = 1;
        r.values[k] = static_cast<float>(values[i]);
    }
    return r;
}

void FalseColour(double t, float rgb[3]) {
    // viridis (matplotlib), sampled at nine points and interpolated linearly.
    static constexpr float kMap[9][3] = {
        {0.267f, 0.005f, 0.329f}, {0.283f, 0.141f, 0.458f}, {0.254f, 0.265f, 0.530f},
        {0.207f, 0.372f, 0.553f}, {0.164f, 0.471f, 0.558f}, {0.128f, 0.567f, 0.551f},
        {0.135f, 0.659f, 0.518f}, {0.477f, 0.821f, 0.318f}, {0.993f, 0.906f, 0.144f}};
    t = std::clamp(std::isfinite(t) ? t : 0., 0., 1.) * 8.;
    const int i = std::min(7, static_cast<int>(t));
    const float f = static_cast<float>(t - i);
    for (int c = 0; c < 3; ++c) rgb[c] = kMap[i][c] * (1 - f) + kMap[i + 1][c] * f;
}

namespace {

std::string Label(double v) {
    char buf[32];
    if (std::fabs(v) >= 1000 && v == std::round(v)) {
        const int n = std::snprintf(buf, sizeof buf, "%.0f", v);
        std::string s;  // thousands separated as in the paper's scale ("20,000 lux")
        for (int i = 0; i < n; ++i) {
            s += buf[i];
            const int left = n - 1 - i;
            if (left > 0 && left % 3 == 0 && buf[i] != '-') s += ',';
        }
        return s;
    }
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

cairo_status_t WriteToOutput(void *closure, const unsigned char *data, unsigned int length) {
    static_cast<OutputFile *>(closure)->Write(data, length);
    return CAIRO_STATUS_SUCCESS;
}

void CheckCairo(cairo_status_t s, const std::string &what) {
    if (s != CAIRO_STATUS_SUCCESS) ErrorExit(what + ": " + cairo_status_to_string(s));
}

}  // namespace

namespace {

// A white line (drawn over a dark edge, readable on any colour) along every edge between two
// sensors' cells that lie on either side of value.
void DrawBoundary(cairo_t *cr, const PlanRaster &plan, double value, double left, double top,
                  double ppc) {
    const auto above = [&](int col, int row) { return plan.At(col, row) >= value; };
    for (const double width : {4.0, 2.0}) {
        if (width > 3)
            cairo_set_source_rgb(cr, 0, 0, 0);
        else
            cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_set_line_width(cr, width);
        cairo_set_line_cap(cr, CAIRO_LINE_CAP_SQUARE);
        for (int row = 0; row < plan.height; ++row)
            for (int col = 0; col < plan.width; ++col) {
                if (!plan.Filled(col, row)) continue;
                const double x = left + (col + 1) * ppc, y = top + (row + 1) * ppc;
                if (col + 1 < plan.width && plan.Filled(col + 1, row) &&
                    above(col, row) != above(col + 1, row)) {
                    cairo_move_to(cr, x, y - ppc);
                    cairo_line_to(cr, x, y);
                }
                if (row + 1 < plan.height && plan.Filled(col, row + 1) &&
                    above(col, row) != above(col, row + 1)) {
                    cairo_move_to(cr, x - ppc, y);
                    cairo_line_to(cr, x, y);
                }
            }
        cairo_stroke(cr);
    }
}

}  // namespace

void WritePlanPng(const std::string &path, const PlanRaster &plan, const PlanStyle &style) {
    const int ppc = std::max(1, style.pixels_per_cell);
    const int plan_w = plan.width * ppc, plan_h = plan.height * ppc;
    const int margin = 16, title_h = style.title.empty() ? 0 : 30, scale_w = 120;
    const int bar_h = std::max(plan_h, 200);
    int width = margin + plan_w + margin + scale_w;
    const int height = title_h + margin + bar_h + 40;
    if (!style.title.empty()) {  // wide enough for the title (measured on a scratch surface)
        cairo_surface_t *probe = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1);
        cairo_t *pc = cairo_create(probe);
        cairo_select_font_face(pc, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                               CAIRO_FONT_WEIGHT_NORMAL);
        cairo_set_font_size(pc, 15);
        cairo_text_extents_t ext;
        cairo_text_extents(pc, style.title.c_str(), &ext);
        width = std::max(width, 2 * margin + static_cast<int>(std::ceil(ext.x_advance)));
        cairo_destroy(pc);
        cairo_surface_destroy(probe);
    }
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

    if (!style.title.empty()) {
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_font_size(cr, 15);
        cairo_move_to(cr, margin, 21);
        cairo_show_text(cr, style.title.c_str());
    }
    const double top = title_h + margin, span = style.max - style.min;
    const auto scaled = [&](double v) { return span > 0 ? (v - style.min) / span : 0.; };
    for (int row = 0; row < plan.height; ++row) {
        for (int col = 0; col < plan.width; ++col) {
            float rgb[3] = {0.35f, 0.35f, 0.35f};  // no sensor: walls, partitions
            if (plan.Filled(col, row)) {
                const double v = plan.At(col, row);
                if (style.white_at >= 0 && v >= style.white_at) {
                    rgb[0] = rgb[1] = rgb[2] = 1;
                } else {
                    FalseColour(scaled(v), rgb);
                }
            }
            cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
            cairo_rectangle(cr, margin + col * ppc, top + row * ppc, ppc, ppc);
            cairo_fill(cr);
        }
    }
    if (style.boundary >= 0) DrawBoundary(cr, plan, style.boundary, margin, top, ppc);
    // An outline, so white cells (LM-83 maps) stand out from the page.
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, margin - 0.5, top - 0.5, plan_w + 1, plan_h + 1);
    cairo_stroke(cr);
    // North arrow at the plan's top right.
    cairo_set_source_rgb(cr, 0.8, 0.1, 0.1);
    const double ax = margin + plan_w - 14, ay = top + 8;
    cairo_move_to(cr, ax, ay);
    cairo_line_to(cr, ax - 6, ay + 16);
    cairo_line_to(cr, ax + 6, ay + 16);
    cairo_close_path(cr);
    cairo_fill(cr);
    cairo_set_font_size(cr, 11);
    cairo_move_to(cr, ax - 4, ay + 30);
    cairo_show_text(cr, "N");

    // The scale: a vertical ramp with six labelled ticks, the unit below.
    const double bx = margin + plan_w + margin, bw = 22;
    for (int y = 0; y < bar_h; ++y) {
        float rgb[3];
        FalseColour(1. - (y + 0.5) / bar_h, rgb);
        cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
        cairo_rectangle(cr, bx, top + y, bw, 1);
        cairo_fill(cr);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_set_font_size(cr, 11);
    for (int k = 0; k <= 5; ++k) {
        const double y = top + bar_h * (1. - k / 5.);
        cairo_move_to(cr, bx + bw, y);
        cairo_line_to(cr, bx + bw + 5, y);
        cairo_stroke(cr);
        const std::string text = Label(style.min + span * k / 5.);
        cairo_move_to(cr, bx + bw + 8, y + 4);
        cairo_show_text(cr, text.c_str());
    }
    if (style.boundary >= 0 && span > 0) {  // the boundary's mark across the scale
        const double y = top + bar_h * (1. - std::clamp(scaled(style.boundary), 0., 1.));
        cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_set_line_width(cr, 3);
        cairo_move_to(cr, bx - 3, y);
        cairo_line_to(cr, bx + bw + 3, y);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_line_width(cr, 1);
    }
    if (style.white_at >= 0) {
        cairo_rectangle(cr, bx + 0.5, top + bar_h + 10.5, bw - 1, 11);
        cairo_stroke(cr);
        const std::string text = ">= " + Label(style.white_at);
        cairo_move_to(cr, bx + bw + 8, top + bar_h + 20);
        cairo_show_text(cr, text.c_str());
    }
    if (!style.unit.empty()) {
        cairo_move_to(cr, bx, top + bar_h + 36);
        cairo_show_text(cr, style.unit.c_str());
    }
    cairo_destroy(cr);
    CheckCairo(cairo_surface_status(surface), path);
    OutputFile out(path);
    const cairo_status_t s = cairo_surface_write_to_png_stream(surface, WriteToOutput, &out);
    cairo_surface_destroy(surface);
    CheckCairo(s, path);
    out.Commit();
}

namespace {

// The plan enlarged to pixels_per_cell pixels a side, times scale, row 0 at the top.
std::vector<float> Enlarge(const PlanRaster &plan, double scale, int ppc, int *w, int *h) {
    *w = plan.width * ppc;
    *h = plan.height * ppc;
    std::vector<float> px(static_cast<size_t>(*w) * *h);
    for (int y = 0; y < *h; ++y)
        for (int x = 0; x < *w; ++x) {
            const int col = x / ppc, row = y / ppc;
            px[static_cast<size_t>(y) * *w + x] =
                plan.Filled(col, row) ? static_cast<float>(plan.At(col, row) * scale) : 0.f;
        }
    return px;
}

}  // namespace

void WritePlanHdr(const std::string &path, const PlanRaster &plan, double scale,
                  int pixels_per_cell) {
    int w, h;
    const std::vector<float> px = Enlarge(plan, scale, std::max(1, pixels_per_cell), &w, &h);
    OutputFile out(path);
    out.Write("#?RADIANCE\nSOFTWARE= dayflux fcplan\nFORMAT=32-bit_rle_rgbe\n\n-Y " +
              std::to_string(h) + " +X " + std::to_string(w) + "\n");
    std::vector<Colr> scan(w);
    std::string bytes;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const float v = px[static_cast<size_t>(y) * w + x];
            scan[x] = ToColr(v, v, v);
        }
        bytes.clear();
        EncodeScanline(scan.data(), w, &bytes);
        out.Write(bytes);
    }
    out.Commit();
}

void WritePlanExr(const std::string &path, const PlanRaster &plan, double scale,
                  int pixels_per_cell) {
    int w, h;
    const std::vector<float> px = Enlarge(plan, scale, std::max(1, pixels_per_cell), &w, &h);
    // OpenEXR seeks in its output, so the picture is made in memory and written as any output
    // is (a FIFO or a device takes it too).
    Imf::StdOSStream stream;
    try {
        Imf::Header header(w, h);
        Imf::FrameBuffer fb;
        for (const char *c : {"R", "G", "B"}) {
            header.channels().insert(c, Imf::Channel(Imf::FLOAT));
            fb.insert(
                c, Imf::Slice(Imf::FLOAT, reinterpret_cast<char *>(const_cast<float *>(px.data())),
                              sizeof(float), sizeof(float) * w));
        }
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(fb);
        file.writePixels(h);
    } catch (const std::exception &e) {
        ErrorExit(path + ": " + e.what());
    }
    OutputFile out(path);
    out.Write(stream.str());
    out.Commit();
}

}  // namespace dayflux
