#include "daysim/project.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "util/files.h"
#include "util/strings.h"

namespace dayflux {

namespace {

// Keys of DAYSIM's other programs (metrics, lighting and blind control, glare, DDS, photon
// maps): accepted and not used here.
const std::set<std::string> &KeysNotUsedHere() {
    static const std::set<std::string> keys = {"AdaptiveZoneApplies",
                                               "DA_max_active_RGB",
                                               "DA_max_passive_RGB",
                                               "DDS_file",
                                               "DDS_sensor_file",
                                               "DGP_Profiles",
                                               "DSP_active_RGB",
                                               "DSP_passive_RGB",
                                               "DirectIrradianceGlareThreshold",
                                               "PNGScheduleExists",
                                               "Template_File",
                                               "UDI_100_2000_active_RGB",
                                               "UDI_100_2000_passive_RGB",
                                               "UDI_100_active_RGB",
                                               "UDI_100_passive_RGB",
                                               "UDI_2000_active_RGB",
                                               "UDI_2000_passive_RGB",
                                               "ballast_driver_schedule",
                                               "bin_directory",
                                               "blind_control",
                                               "calc_grid",
                                               "continuous_daylight_autonomy_active_RGB",
                                               "continuous_daylight_autonomy_passive_RGB",
                                               "daylight_autonomy",
                                               "daylight_autonomy_active_RGB",
                                               "daylight_autonomy_passive_RGB",
                                               "daylight_availability_active_RGB",
                                               "daylight_availability_passive_RGB",
                                               "daylight_factor",
                                               "daylight_factor_RGB",
                                               "daylight_savings_time",
                                               "dgp_check_file",
                                               "dgp_image_x_size",
                                               "dgp_image_y_size",
                                               "dgp_out_file",
                                               "dgp_profile_cut",
                                               "direct_glare_file",
                                               "direct_radiance_file_2305",
                                               "direct_sunlight_file",
                                               "display_unit_index",
                                               "electric_lighting",
                                               "electric_lighting_system",
                                               "first_weekday",
                                               "input_unit_index",
                                               "luminaire_layout",
                                               "luminaire_schedule",
                                               "material_directory",
                                               "minimum_illuminance_level",
                                               "occupancy",
                                               "occupancy_profile",
                                               "output_unit_index",
                                               "percentage_of_visible_sky_file",
                                               "photosensor_control",
                                               "radiance_source_files",
                                               "rshow_da",
                                               "rshow_df",
                                               "sDA_settings",
                                               "scene_rotation_angle",
                                               "sensor_file_info",
                                               "target_illuminance",
                                               "thermal_simulation",
                                               "thermal_simulation_active",
                                               "thermal_simulation_passive",
                                               "user_profile",
                                               "viewpoint_file",
                                               "wea_data_file",
                                               "zone_description",
                                               "pmap_apD",
                                               "pmap_apc_bwidth",
                                               "pmap_apc_file",
                                               "pmap_apc_nphotons",
                                               "pmap_apg_bwidth",
                                               "pmap_apg_file",
                                               "pmap_apg_nphotons",
                                               "pmap_apo",
                                               "pmap_t",
                                               "sj",
                                               "dc_direct_resolution",
                                               "solar_pen",
                                               "perez_output",
                                               "horizon_data_out",
                                               "horizon_data_in",
                                               "all_warnings",
                                               "ds_shortterm"};
    return keys;
}

class HeaReader {
  public:
    HeaReader(const std::string &file, DaysimProject *p) : p_(*p), in_(InputSource::Open(file)) {
        p_.file = file;
    }

    void Run() {
        std::string line;
        DaysimRtraceSettings *block = nullptr;  // inside <direct_rtrace> or <diffuse_rtrace>
        FileLoc opened;
        while (true) {
            loc_ = in_->Loc();
            if (!in_->ReadLine(&line)) break;
            words_ = SplitWords(line.substr(0, line.find('#')));
            if (words_.empty()) continue;
            const std::string key = words_[0];
            if (key == "<direct_rtrace>" || key == "<direct-rtrace>") {
                block = &p_.direct, opened = loc_;
            } else if (key == "<diffuse_rtrace>" || key == "<diffuse-rtrace>") {
                block = &p_.diffuse, opened = loc_;
            } else if (key.rfind("</", 0) == 0 && block) {
                block = nullptr;
            } else if (block) {
                if (!Rtrace(key, block)) Fail(key, "is not an rtrace setting");
            } else if (!Project(key) && !Site(key) && !Scene(key) && !Both(key)) {
                if (KeysNotUsedHere().count(key) == 0)
                    Warning(&loc_,
                            "unknown key '" + key + "' (ignored, as DAYSIM does: misspelled?)");
            }
            p_.where[key] = loc_;
        }
        if (block) ErrorExit(&opened, "this rtrace block is not closed");
    }

  private:
    [[noreturn]] void Fail(const std::string &key, const std::string &why) {
        ErrorExit(&loc_, "'" + key + "' " + why);
    }
    std::string Word(const std::string &key, size_t k = 1) {
        if (words_.size() <= k) Fail(key, "needs a value");
        return words_[k];
    }
    // The rest of the line after the key (paths with spaces: project_directory).
    std::string Rest(const std::string &key) {
        Word(key);
        std::string s;
        for (size_t k = 1; k < words_.size(); ++k) s += (k > 1 ? " " : "") + words_[k];
        return s;
    }
    double Number(const std::string &key, size_t k = 1) {
        double v;
        const std::string w = Word(key, k);
        if (!ParseNumber(w, &v) || !std::isfinite(v)) Fail(key, "has a bad number '" + w + "'");
        return v;
    }
    int Integer(const std::string &key, size_t k = 1) {
        const double v = Number(key, k);
        if (std::fabs(v) > 1e9 || v != std::floor(v))
            Fail(key, "needs a whole number, not " + words_[k]);
        return static_cast<int>(v);
    }

    bool Project(const std::string &key) {
        if (key == "project_name") {
            p_.project_name = Word(key);
        } else if (key == "project_directory") {
            p_.project_directory = Rest(key);
        } else if (key == "tmp_directory") {
            p_.tmp_directory = Word(key);
        } else if (key == "place") {
            p_.place = Word(key);
        } else if (key == "shading") {
            Shading(key);
        } else if (key == "coupling_mode") {
            p_.coupling_mode = Integer(key);
            if (p_.coupling_mode != 0 && p_.coupling_mode != 3)
                Fail(key, "mode " + words_[1] + " is not supported (0: interpolated, 3: no sun)");
        } else if (key == "rotate_x" || key == "rotate_y" || key == "rotate_z") {
            Fail(key, "(rotating the scene and sensors) is not supported");
        } else {
            return false;
        }
        return true;
    }

    bool Site(const std::string &key) {
        if (key == "latitude") {
            p_.latitude = Number(key);
            if (std::abs(*p_.latitude) > 90) Fail(key, "lies outside -90..90");
        } else if (key == "longitude") {
            p_.longitude = Number(key);
            if (std::abs(*p_.longitude) > 180) Fail(key, "lies outside -180..180");
        } else if (key == "time_zone") {
            p_.time_zone = Number(key);
            if (std::abs(*p_.time_zone) > 180) Fail(key, "lies outside -180..180");
        } else if (key == "site_elevation") {
            p_.site_elevation = Number(key);
        } else if (key == "ground_reflectance") {
            p_.ground_reflectance = Number(key);
        } else if (key == "time_step") {
            p_.time_step = Integer(key);
            if (p_.time_step < 1 || 60 % p_.time_step != 0)
                Fail(key, "must divide 60 minutes (60, 30, 20, 15, 12, 10, 6, 5, 4, 3, 2, 1)");
        } else if (key == "wea_data_short_file") {
            p_.weather = Word(key);
        } else if (key == "wea_data_short_file_units" || key == "wea_data_file_units" ||
                   key == "input_format_genweather" || key == "input_type" ||
                   key == "input_weather_data_shortterm" || key == "input_irradiance_data") {
            if (key == "wea_data_short_file_units") {
                p_.weather_units = Integer(key);
                if (p_.weather_units < 1 || p_.weather_units > 3)
                    Fail(key, "must be 1 (DNI, DHI W/m2), 2 (GHI, DHI W/m2) or 3 (lux)");
            }
        } else if (key == "lower_direct_threshold") {
            p_.direct_threshold = Number(key);
        } else if (key == "lower_diffuse_threshold") {
            p_.diffuse_threshold = Number(key);
        } else if (key == "output_units") {
            p_.output_units = Integer(key);
        } else {
            return false;
        }
        return true;
    }

    bool Scene(const std::string &key) {
        if (key == "material_file" || key == "geometry_file") {
            Word(key);
            std::vector<std::string> &files =
                key == "material_file" ? p_.material_files : p_.geometry_files;
            files.assign(words_.begin() + 1, words_.end());
        } else if (key == "sensor_file") {
            p_.sensor_file = Word(key);
        } else if (key == "sensor_file_unit") {
            p_.sensor_units.clear();
            for (size_t k = 1; k < words_.size(); ++k) {
                const int u = Integer(key, k);
                if (u < 0 || u > 3) Fail(key, "unit " + words_[k] + " is not 0, 1, 2 or 3");
                p_.sensor_units.push_back(u);
            }
            p_.sensor_units_loc = loc_;
        } else if (key == "direct_radiance_file") {
            p_.direct_radiance_file = Word(key);
        } else {
            return false;
        }
        return true;
    }

    // rtrace settings outside a block apply to both runs.
    bool Both(const std::string &key) {
        DaysimRtraceSettings d = p_.direct, f = p_.diffuse;
        if (!Rtrace(key, &d)) return false;
        Rtrace(key, &f);
        p_.direct = d, p_.diffuse = f;
        return true;
    }

    bool Rtrace(const std::string &key, DaysimRtraceSettings *s) {
        if (key == "aa")
            s->aa = Number(key);
        else if (key == "ab")
            s->ab = Integer(key);
        else if (key == "ad")
            s->ad = Integer(key);
        else if (key == "ar")
            s->ar = Integer(key);
        else if (key == "as")
            s->as = Integer(key);
        else if (key == "dj")
            s->dj = Number(key);
        else if (key == "ds")
            s->ds = Number(key);
        else if (key == "dp")
            s->dp = Number(key);
        else if (key == "dr")
            s->dr = Integer(key);
        else if (key == "lr")
            s->lr = Integer(key);
        else if (key == "lw")
            s->lw = Number(key);
        else if (key == "st")
            s->st = Number(key);
        else if (key == "ss")
            Number(key);  // gen_dc always passes -ss 1 (DAYSIM's sj)
        else if (key == "irradiance_switch")
            s->irradiance_switch = Word(key);
        else if (key == "additional_rtrace_parameter")
            s->additional = Rest(key);
        else if (key == "calculation_mode") {
            if (Word(key) != "classic") Fail(key, "photon maps are not supported");
        } else
            return false;
        return true;
    }

    // shading 1 name dc ill; shading 0 name dc ill ill_down (the simple blinds model);
    // shading n>=2: n x (name scene dc ill). Values may continue on the next lines.
    void Shading(const std::string &key) {
        const int n = Integer(key);
        if (n < 0 || n > 10)
            Fail(key, "models with blind groups (" + words_[1] + ") are not supported (0..10)");
        const size_t per = n >= 2 ? 4 : 3, want = 2 + (n == 0 ? 4 : per * std::max(n, 1));
        std::string line;
        while (words_.size() < want && in_->ReadLine(&line)) {
            for (const std::string &w : SplitWords(line.substr(0, line.find('#'))))
                words_.push_back(w);
        }
        if (words_.size() < want) Fail(key, "needs " + std::to_string(want - 2) + " names");
        p_.simple_blinds = n == 0;
        p_.variants.clear();
        for (int v = 0; v < std::max(n, 1); ++v) {
            const size_t b = 2 + v * per;
            DaysimVariant var;
            var.name = words_[b];
            if (per == 4) var.scene = words_[b + 1];
            var.dc = words_[b + per - 2];
            var.ill = words_[b + per - 1];
            if (n == 0) var.ill_blinds_down = words_[b + 3];
            p_.variants.push_back(var);
        }
    }

    DaysimProject &p_;
    std::unique_ptr<InputSource> in_;
    std::vector<std::string> words_;
    FileLoc loc_;
};

}  // namespace

void DaysimProject::Require(const std::string &key, bool present) const {
    if (!present) {
        const FileLoc loc{file, 0};
        ErrorExit(&loc, "the key '" + key + "' is missing");
    }
}

std::string DaysimProject::Path(const std::string &name) const {
    if (name.empty() || name[0] == '/' || project_directory.empty()) return name;
    return (std::filesystem::path(project_directory) / name).string();
}

size_t CountSensors(const std::string &file) {
    const std::unique_ptr<InputSource> in = InputSource::Open(file);
    std::string line;
    size_t n = 0;
    FileLoc blank;  // the first blank line since the last sensor: an error if a sensor follows
    while (true) {
        const FileLoc loc = in->Loc();
        if (!in->ReadLine(&line)) break;
        const std::vector<std::string> w = SplitWords(line);
        if (w.empty()) {
            if (blank.file.empty()) blank = loc;
            continue;
        }
        if (!blank.file.empty())
            ErrorExit(&blank, "an empty line among the sensors (every line is a sensor)");
        double v;
        if (w.size() < 6) ErrorExit(&loc, "a sensor needs six numbers (x y z dx dy dz)");
        for (int k = 0; k < 6; ++k)
            if (!ParseNumber(w[k], &v) || !(std::fabs(v) <= 1e12))
                ErrorExit(&loc, "'" + w[k] + "' is not a coordinate");
        ++n;
    }
    if (n == 0) ErrorExit(file + ": no sensors");
    return n;
}

DaysimProject ReadDaysimProject(const std::string &file) {
    DaysimProject p;
    HeaReader(file, &p).Run();
    return p;
}

}  // namespace dayflux
