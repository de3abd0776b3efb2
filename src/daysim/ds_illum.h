// ds_illum: DAYSIM's annual illuminances from a project's daylight coefficients (.dc) and its
// weather (.wea): at each time step the Perez all-weather sky (its 1990 efficacies and 1993
// luminance model, as DAYSIM's calculate_Perez.c evaluates them) at DAYSIM's 145 patch centres and
// three ground directions, and the sun shared between the four direct coefficients nearest it
// (two design days, two hours), summed per sensor into the .ill file: a line per step,
// `month day hour` and a value per sensor (lux, cd/m2 or W/m2 by sensor_file_unit).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "daysim/project.h"

namespace dayflux {

struct DsIllumOptions {
    std::string extension;  // -ext: added to the sensor, .dc and .ill names
};

void RunDsIllum(const DaysimProject &project, const DsIllumOptions &options);

// A .dc file's coefficients, a row per sensor ('#' lines skipped): exactly `sensors` rows of
// `columns` numbers, else an error naming the file and line.
std::vector<std::vector<float>> ReadDaysimDc(const std::string &file, size_t sensors,
                                             int columns);

// One time step's sky as ds_illum builds it: luminance (cd/m2) and radiance (W/m2 sr) of the
// 148 diffuse patches and of the direct coefficients the sun is shared between (index 148 + k),
// zero where the step is dark.
struct DaysimStepSky {
    bool dark = true;     // night, or diffuse below its threshold: every value 0
    bool direct = false;  // the sun's coefficients take part (direct above its threshold)
    std::vector<float> luminance, radiance;
};

class DaysimSkyModel {
  public:
    // columns: 148 + the direct coefficients.
    DaysimSkyModel(const DaysimProject &project, int columns);
    // A .wea record (hour: decimal local standard time) with the .hea's units.
    DaysimStepSky Step(int month, int day, double hour, double dir, double dif) const;

  private:
    struct Impl;
    std::shared_ptr<const Impl> impl_;
};

}  // namespace dayflux
