// DAYSIM's project file (.hea): a keyword and its values per line, '#' comments, as gen_dc and
// ds_illum read it (DAYSIM's read_in_header.c): the site, the weather, the scene, the sensors,
// the shading variants with their .dc and .ill files, and rtrace's settings. Relative paths are
// taken from project_directory (DAYSIM pastes the two strings together; we join them as paths).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux {

// rtrace_dc's settings of one run (gen_dc's defaults, DAYSIM's initRadianceOptions).
struct DaysimRtraceSettings {
    double aa = 0.2;
    int ab = 0, ad = 512, ar = 128, as = 0;
    double dj = 0, ds = 0.2, dp = 512;
    int dr = 2, lr = 6;
    double lw = 0.004, st = 0.15;
    std::string irradiance_switch = "I+";
    std::string additional;  // additional_rtrace_parameter
};

// One shading variant: its name, extra scene file (variants after the first of an intermediate
// model), daylight coefficient file and illuminance file(s).
struct DaysimVariant {
    std::string name, scene, dc, ill;
    std::string ill_blinds_down;  // shading 0: the simple blinds model's second file
};

struct DaysimProject {
    std::string file;  // the .hea itself
    std::string project_name, project_directory, tmp_directory = ".", place;
    // Degrees as the .hea gives them: latitude north, longitude and time_zone (the standard
    // meridian) west positive, as RADIANCE's programs take them.
    std::optional<double> latitude, longitude, time_zone;
    double site_elevation = 0, ground_reflectance = 0;  // DAYSIM's defaults
    int time_step = 5;      // minutes; DAYSIM's default when the key is missing (warned)
    std::string weather;    // wea_data_short_file
    int weather_units = 1;  // 1 DNI/DHI W/m2, 2 global/diffuse horizontal W/m2, 3 lux
    double direct_threshold = 0, diffuse_threshold = 0;  // lower_*_threshold, W/m2
    int output_units = 2;
    // material_file and geometry_file (each may name several files)
    std::vector<std::string> material_files, geometry_files;
    std::string sensor_file;
    std::vector<int> sensor_units;  // 0 lux, 1 cd/m2, 2 W/m2, 3 W/m2sr; empty: all 0
    FileLoc sensor_units_loc;
    std::vector<DaysimVariant> variants;
    bool simple_blinds = false;  // shading 0
    std::string direct_radiance_file;
    int coupling_mode = 0;
    DaysimRtraceSettings direct, diffuse;
    // Where each key was read, for messages about its value.
    std::map<std::string, FileLoc> where;

    // Errors naming the .hea and the key when a program needs a key that is not there.
    void Require(const std::string &key, bool present) const;
    // A path from the .hea, relative to project_directory.
    std::string Path(const std::string &name) const;
};

// Reads a .hea; bad values are errors with file and line; keys DAYSIM has but we do not use
// are accepted, keys DAYSIM does not know get a warning (a misspelled key is otherwise lost, as
// DAYSIM skips the line).
DaysimProject ReadDaysimProject(const std::string &file);

// The sensors of a sensor file (x y z dx dy dz per line; '#' lines and blank lines are errors, as
// they would shift the rows of every file after).
size_t CountSensors(const std::string &file);

}  // namespace dayflux
