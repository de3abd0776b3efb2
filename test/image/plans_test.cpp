// Floor plans: rasterising sensor grids, and the PNG, HDR and EXR files read back.
#include "image/plans.h"

#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "matrix/reader.h"
#include "test_util.h"
#include "util/errors.h"

namespace dayflux::test {
namespace {

// A 3 x 2 cell-centred grid (0.5 m cells) with value 10 * column + row (row 0 south).
void Grid(std::vector<SensorPoint> *pts, std::vector<double> *values) {
    for (int r = 0; r < 2; ++r)
        for (int c = 0; c < 3; ++c) {
            pts->push_back(SensorPoint{0.25 + 0.5 * c, 0.25 + 0.5 * r, 0.8,
                                       FileLoc{"grid.pts", static_cast<int>(pts->size()) + 1}});
            values->push_back(10 * c + r);
        }
}

TEST(Plans, RasterNorthUpAndGaps) {
    std::vector<SensorPoint> pts;
    std::vector<double> v;
    Grid(&pts, &v);
    PlanRaster r = RasterizePlan(pts, v);
    ASSERT_EQ(r.width, 3);
    ASSERT_EQ(r.height, 2);
    EXPECT_DOUBLE_EQ(r.cell_x, 0.5);
    EXPECT_EQ(r.At(2, 0), 21);  // north row first
    EXPECT_EQ(r.At(2, 1), 20);
    // A second office 1 m to the east leaves a column of empty cells between them.
    pts.push_back(SensorPoint{0.25 + 2.0, 0.25, 0.8, FileLoc{"grid.pts", 7}});
    v.push_back(99);
    r = RasterizePlan(pts, v);
    ASSERT_EQ(r.width, 5);
    EXPECT_FALSE(r.Filled(3, 1));
    EXPECT_TRUE(r.Filled(4, 1));
    EXPECT_EQ(r.At(4, 1), 99);
    // Two sensors in one cell: not a grid.
    pts.push_back(SensorPoint{0.25 + 2.0, 0.25 + 1e-9, 0.8, FileLoc{"grid.pts", 8}});
    v.push_back(1);
    try {
        RasterizePlan(pts, v);
        ADD_FAILURE() << "two sensors in one cell were accepted";
    } catch (const UserError &e) {
        EXPECT_NE(std::string(e.what()).find("grid.pts:8: this sensor and the one at grid.pts:7"),
                  std::string::npos)
            << e.what();
    }
}

TEST(Plans, FalseColourEndsAndClamps) {
    float lo[3], hi[3], below[3], above[3];
    FalseColour(0, lo);
    FalseColour(1, hi);
    FalseColour(-5, below);
    FalseColour(7, above);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(lo[c], below[c]);
        EXPECT_EQ(hi[c], above[c]);
    }
    EXPECT_GT(hi[0] + hi[1], lo[0] + lo[1]);  // dark to bright
}

TEST(Plans, PicturesReadBack) {
    std::vector<SensorPoint> pts;
    std::vector<double> v;
    Grid(&pts, &v);
    const PlanRaster r = RasterizePlan(pts, v);
    TempDir tmp;
    const std::string png = (tmp.path() / "p.png").string(), hdr = (tmp.path() / "p.hdr").string(),
                      exr = (tmp.path() / "p.exr").string();
    PlanStyle style;
    style.title = "test";
    style.max = 30;
    WritePlanPng(png, r, style);
    const std::string bytes = ReadFile(png);
    ASSERT_GT(bytes.size(), 24u);
    EXPECT_EQ(bytes.substr(1, 3), "PNG");
    WritePlanHdr(hdr, r, 0.5, 2);
    MatrixReader pic(hdr);
    ASSERT_EQ(pic.Rows(), 4);
    ASSERT_EQ(pic.Cols(), 6);
    std::vector<float> row(6 * 3);
    pic.ReadRow(row.data());  // the north row: values 1, 11, 21 x 0.5, two pixels each
    EXPECT_NEAR(row[0], 0.5, 0.5 * 0.01);
    EXPECT_NEAR(row[2 * 3], 5.5, 5.5 * 0.01);
    EXPECT_NEAR(row[5 * 3 + 2], 10.5, 10.5 * 0.01);
    WritePlanExr(exr, r, 0.5, 1);
    Imf::InputFile in(exr.c_str());
    const auto dw = in.header().dataWindow();
    ASSERT_EQ(dw.max.x - dw.min.x + 1, 3);
    ASSERT_EQ(dw.max.y - dw.min.y + 1, 2);
    std::vector<float> g(6);
    Imf::FrameBuffer fb;
    fb.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char *>(g.data()), sizeof(float),
                              3 * sizeof(float)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    EXPECT_EQ(g, (std::vector<float>{0.5f, 5.5f, 10.5f, 0.f, 5.f, 10.f}));
}

// The pixels two PNGs differ in.
int DifferentPixels(const std::string &a, const std::string &b) {
    cairo_surface_t *x = cairo_image_surface_create_from_png(a.c_str()),
                    *y = cairo_image_surface_create_from_png(b.c_str());
    int n = -1;
    if (cairo_surface_status(x) == CAIRO_STATUS_SUCCESS &&
        cairo_surface_status(y) == CAIRO_STATUS_SUCCESS &&
        cairo_image_surface_get_height(x) == cairo_image_surface_get_height(y)) {
        cairo_surface_flush(x);
        cairo_surface_flush(y);
        const int h = cairo_image_surface_get_height(x), stride = cairo_image_surface_get_stride(x);
        const unsigned char *p = cairo_image_surface_get_data(x),
                            *q = cairo_image_surface_get_data(y);
        n = 0;
        for (int i = 0; i < h * stride; i += 4) n += std::memcmp(p + i, q + i, 4) != 0;
    }
    cairo_surface_destroy(x);
    cairo_surface_destroy(y);
    return n;
}

// -b: a line between the cells on either side of the value, over the full colour scale (values
// 0 1 10 11 20 21: a line between the columns of 10s and 20s at 15), and a mark on the scale
// alone where no cells straddle it (at 25).
TEST(Plans, BoundaryBetweenCellsOnEitherSide) {
    std::vector<SensorPoint> pts;
    std::vector<double> v;
    Grid(&pts, &v);
    const PlanRaster r = RasterizePlan(pts, v);
    TempDir tmp;
    PlanStyle style;
    style.max = 30;
    const auto png = [&](double boundary) {
        style.boundary = boundary;
        const std::string path = (tmp.path() / ("b" + std::to_string(boundary) + ".png")).string();
        WritePlanPng(path, r, style);
        return path;
    };
    const std::string none = png(-1), between = png(15), above = png(25);
    const int line = DifferentPixels(none, between), mark = DifferentPixels(none, above);
    EXPECT_GT(mark, 0);
    EXPECT_GT(line, mark + 2 * 16);  // two cells' edge (16 pixels a cell), with its width
}

TEST(Plans, SensorPointErrors) {
    TempDir tmp;
    WriteFile(tmp.path() / "a.pts", "0 0 0 0 0 1\n1 1 x 0 0 1\n");
    WriteFile(tmp.path() / "b.pts", "0 0 0 0 0 1\n\n1 1 1\n");
    try {
        ReadSensorPoints((tmp.path() / "a.pts").string());
        ADD_FAILURE();
    } catch (const UserError &e) {
        EXPECT_NE(std::string(e.what()).find("a.pts:2: 'x'"), std::string::npos) << e.what();
    }
    try {
        ReadSensorPoints((tmp.path() / "b.pts").string());
        ADD_FAILURE();
    } catch (const UserError &e) {
        EXPECT_NE(std::string(e.what()).find("b.pts:3: a sensor point needs 6 numbers"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace dayflux::test
