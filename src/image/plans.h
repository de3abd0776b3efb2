// Floor plans of sensor values: sensors on a regular grid become the cells of a raster, which
// is written as a false-colour PNG with a scale, or as RADIANCE HDR / OpenEXR for other tools.
#pragma once

#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux {

struct SensorPoint {
    double x = 0, y = 0, z = 0;
    FileLoc loc;  // where it was read, for messages
};

// Reads sensor points ("x y z dx dy dz" per line, as rtrace and rcontrib take them); errors
// name file and line.
std::vector<SensorPoint> ReadSensorPoints(const std::string &path);

// Values on a plan: cell (column, row) with row 0 at the north (largest y), as a plan is drawn.
struct PlanRaster {
    int width = 0, height = 0;
    double cell_x = 0, cell_y = 0;      // cell size, model units
    std::vector<float> values;          // width x height, row-major
    std::vector<unsigned char> filled;  // 1 where a sensor lies
    float At(int col, int row) const { return values[static_cast<size_t>(row) * width + col]; }
    bool Filled(int col, int row) const { return filled[static_cast<size_t>(row) * width + col]; }
};

// Places each sensor's value in the cell of a grid whose spacing is the smallest spacing of the
// sensors in x and in y. Two sensors in one cell, or a grid over 4096 cells a side, are errors.
PlanRaster RasterizePlan(const std::vector<SensorPoint> &points, const std::vector<double> &values);

// A perceptually uniform colour map (viridis), t in [0, 1] -> RGB in [0, 1].
void FalseColour(double t, float rgb[3]);

struct PlanStyle {
    std::string title;          // drawn above the plan
    std::string unit;           // drawn under the scale ("lux", "% of occupied hours")
    double min = 0, max = 100;  // the scale's ends; values outside are clamped
    int pixels_per_cell = 16;
    double white_at = -1;  // >= 0: cells at or above this are drawn white (LM-83 maps)
    // >= 0: a line between neighbouring cells on either side of this value (DA = 50 %), over
    // the full colour scale, and the same mark on the scale (DIVA's and Ladybug's plans)
    double boundary = -1;
};

// Writes a PNG of the plan with a title, a north arrow and a labelled colour scale. The file is
// written to a temporary and renamed.
void WritePlanPng(const std::string &path, const PlanRaster &plan, const PlanStyle &style);
// Writes the raster as a RADIANCE picture (grey, value x scale per channel), pixels_per_cell
// pixels a side per cell; empty cells are 0.
void WritePlanHdr(const std::string &path, const PlanRaster &plan, double scale,
                  int pixels_per_cell);
// The same as an OpenEXR file with 32-bit float R, G and B.
void WritePlanExr(const std::string &path, const PlanRaster &plan, double scale,
                  int pixels_per_cell);

}  // namespace dayflux
