// Weather files: DAYSIM/RADIANCE .wea (units 1, 2, 3) and EnergyPlus .epw, read record by record
// with every problem reported by file and line.
#pragma once

#include <memory>
#include <string>

#include "util/files.h"

namespace dayflux {

// The most the sun gives above the atmosphere (1361 W/m2, 1.5 x 10^5 lux normal to it), with a
// margin that keeps extreme real records: more is a spike in the data.
constexpr double kMostIrradiance = 1500, kMostIlluminance = 200000;

struct WeatherHeader {
    std::string place;
    double latitude = 0;         // degrees north
    double longitude = 0;        // degrees WEST (RADIANCE's convention)
    double time_zone = 0;        // standard meridian, degrees west (-15 x UTC offset)
    std::string elevation_text;  // as written (epw2wea copies it)
    double elevation = 0;        // metres
    int units = 1;               // 1: DNI/DHI W/m2, 2: direct horizontal/DHI W/m2, 3: lux
    // From an EPW file: the original fields epw2wea prints.
    std::string epw_latitude_text;
    double epw_time_zone_hours = 0;
    int records_per_hour = 1;
};

struct WeatherRecord {
    int month = 0, day = 0;
    double hour = 0;  // decimal local standard time
    double dir = 0;   // direct (normal, or horizontal for units 2) irradiance or illuminance
    double dif = 0;   // diffuse horizontal
    int line = 0;
};

class WeatherReader {
  public:
    // path: a .wea or .epw file (EPW recognised by its LOCATION line), or "-" for stdin.
    explicit WeatherReader(const std::string &path);
    const WeatherHeader &Header() const { return header_; }
    bool IsEpw() const { return epw_; }
    const std::string &Name() const { return in_->Name(); }
    // Reads the next record; false at the end. Malformed lines and impossible values throw.
    bool Next(WeatherRecord *rec);

  private:
    void ReadWeaHeader();
    void ReadEpwHeader(const std::string &first_line);
    bool NextWea(WeatherRecord *rec);
    bool NextEpw(WeatherRecord *rec);
    [[noreturn]] void Fail(int line, const std::string &msg) const;
    void Check(const WeatherRecord &rec) const;

    std::unique_ptr<InputSource> in_;
    WeatherHeader header_;
    bool epw_ = false;
    std::string line_;
};

}  // namespace dayflux
