#include "sky/weather.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "util/strings.h"

namespace dayflux {

namespace {

std::vector<std::string> SplitCsv(const std::string &line) {
    std::vector<std::string> fields;
    std::string field;
    std::istringstream ss(line);
    while (std::getline(ss, field, ',')) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.emplace_back();
    return fields;
}

int DaysInMonth(int month) {
    static constexpr int days[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return days[month - 1];
}

}  // namespace

WeatherReader::WeatherReader(const std::string &path) : in_(InputSource::Open(path)) {
    std::string first;
    if (!in_->ReadLine(&first)) Fail(1, "empty weather file");
    if (!first.empty() && first.back() == '\r') first.pop_back();
    if (first.rfind("LOCATION,", 0) == 0) {
        epw_ = true;
        ReadEpwHeader(first);
    } else {
        line_ = first;
        ReadWeaHeader();
    }
}

void WeatherReader::Fail(int line, const std::string &msg) const {
    FileLoc loc{in_->Name(), line};
    ErrorExit(&loc, msg);
}

void WeatherReader::ReadWeaHeader() {
    struct Key {
        const char *name;
        const char *what;
    };
    static constexpr Key keys[] = {
        {"place", "a place name"},     {"latitude", "degrees north"},
        {"longitude", "degrees west"}, {"time_zone", "the standard meridian in degrees west"},
        {"site_elevation", "metres"},  {"weather_data_file_units", "1, 2 or 3"}};
    for (int k = 0; k < 6; ++k) {
        const int lineno = k + 1;
        if (k > 0) {
            if (!in_->ReadLine(&line_))
                Fail(lineno, std::string("missing '") + keys[k].name + "' line in header");
            if (!line_.empty() && line_.back() == '\r') line_.pop_back();
        }
        std::string name = keys[k].name;
        std::string trimmed = Trim(line_);
        if (trimmed.rfind(name, 0) != 0 ||
            (trimmed.size() > name.size() &&
             !std::isspace(static_cast<unsigned char>(trimmed[name.size()]))))
            Fail(lineno, "expected '" + name + " <" + keys[k].what + ">' in the header, found '" +
                             trimmed.substr(0, 60) + "'");
        std::string value = Trim(trimmed.substr(name.size()));
        if (k == 0) {
            header_.place = value;
            continue;
        }
        double v = 0;
        if (!ParseNumber(value, &v) || !std::isfinite(v))
            Fail(lineno, "'" + name + "' needs a number, found '" + value + "'");
        switch (k) {
            case 1:
                if (std::fabs(v) > 90) Fail(lineno, "latitude " + value + " is outside -90..90");
                header_.latitude = v;
                break;
            case 2:
                if (std::fabs(v) > 360)
                    Fail(lineno, "longitude " + value + " is outside -360..360");
                header_.longitude = v;
                break;
            case 3:
                if (std::fabs(v) > 360)
                    Fail(lineno, "time_zone " + value + " is outside -360..360 (degrees west)");
                header_.time_zone = v;
                break;
            case 4:
                header_.elevation = v;
                header_.elevation_text = value;
                break;
            case 5:
                if (v != 1 && v != 2 && v != 3)
                    Fail(lineno, "weather_data_file_units must be 1, 2 or 3, not " + value);
                header_.units = static_cast<int>(v);
                break;
        }
    }
}

void WeatherReader::ReadEpwHeader(const std::string &first) {
    std::vector<std::string> f = SplitCsv(first);
    if (f.size() < 10)
        Fail(1, "EPW LOCATION line has " + std::to_string(f.size()) + " fields, expected 10");
    header_.place = f[1] + "_" + f[3];
    double lat, lon, tz, elev;
    if (!ParseNumber(Trim(f[6]), &lat) || std::fabs(lat) > 90)
        Fail(1, "bad latitude '" + f[6] + "' in LOCATION line");
    if (!ParseNumber(Trim(f[7]), &lon) || std::fabs(lon) > 180)
        Fail(1, "bad longitude '" + f[7] + "' in LOCATION line");
    if (!ParseNumber(Trim(f[8]), &tz) || std::fabs(tz) > 14)
        Fail(1, "bad time zone '" + f[8] + "' in LOCATION line");
    std::string elev_text = Trim(f[9]);
    if (!ParseNumber(elev_text, &elev)) Fail(1, "bad elevation '" + f[9] + "' in LOCATION line");
    header_.epw_latitude_text = f[6];
    header_.latitude = lat;
    header_.longitude = -lon;
    header_.epw_time_zone_hours = tz;
    header_.time_zone = -15.0 * tz;
    header_.elevation = elev;
    header_.elevation_text = elev_text;
    header_.units = 1;
    // Lines 2-7: design conditions, extremes, ground temperatures, holidays, comments.
    for (int i = 2; i <= 8; ++i) {
        if (!in_->ReadLine(&line_)) Fail(i, "EPW header ends early");
        if (i == 8) {
            std::vector<std::string> p = SplitCsv(line_);
            int rph = 1;
            if (p.empty() || Trim(p[0]) != "DATA PERIODS" || p.size() < 3 ||
                !ParseInt(Trim(p[2]), &rph) || rph < 1 || rph > 60 || 60 % rph)
                Fail(8, "expected 'DATA PERIODS,<n>,<records per hour>,...' on line 8");
            header_.records_per_hour = rph;
        }
    }
}

void WeatherReader::Check(const WeatherRecord &r) const {
    if (r.month < 1 || r.month > 12)
        Fail(r.line, "month " + std::to_string(r.month) + " is not 1..12");
    if (r.day < 1 || r.day > DaysInMonth(r.month))
        Fail(r.line, "day " + std::to_string(r.day) + " does not exist in month " +
                         std::to_string(r.month));
    if (!(r.hour >= 0 && r.hour <= 24)) Fail(r.line, "hour is outside 0..24");
    if (!(r.dir >= 0) || !(r.dif >= 0)) Fail(r.line, "negative or non-numeric radiation value");
    // Beyond what the sun gives above the atmosphere (1361 W/m2, 1.5 x 10^5 lux normal to it):
    // a spike in the data, which would turn into NaN patches and negative skies (gendaymtx
    // takes it); the margin keeps extreme real records.
    const bool photometric = header_.units == 3;
    const double most = photometric ? kMostIlluminance : kMostIrradiance;
    const char *unit = photometric ? " lux" : " W/m2";
    if (r.dir > most || r.dif > most)
        Fail(r.line, FormatNumber(r.dir) + unit + " direct, " + FormatNumber(r.dif) + unit +
                         " diffuse: more than the sun can give (at most " +
                         std::to_string(static_cast<int>(most)) + unit + ")");
}

bool WeatherReader::NextWea(WeatherRecord *r) {
    for (;;) {
        const int lineno = in_->Line();
        if (!in_->ReadLine(&line_)) return false;
        std::istringstream ss(line_);
        std::string w[5];
        int n = 0;
        while (n < 5 && ss >> w[n]) ++n;
        if (n == 0) continue;  // blank line
        if (n < 5)
            Fail(lineno, "expected 'month day hour direct diffuse', found '" +
                             Trim(line_).substr(0, 60) + "'");
        r->line = lineno;
        if (!ParseInt(w[0], &r->month) || !ParseInt(w[1], &r->day) ||
            !ParseNumber(w[2], &r->hour) || !ParseNumber(w[3], &r->dir) ||
            !ParseNumber(w[4], &r->dif))
            Fail(lineno, "non-numeric field in '" + Trim(line_).substr(0, 60) + "'");
        Check(*r);
        return true;
    }
}

bool WeatherReader::NextEpw(WeatherRecord *r) {
    for (;;) {
        const int lineno = in_->Line();
        if (!in_->ReadLine(&line_)) return false;
        if (Trim(line_).empty()) continue;
        std::vector<std::string> f = SplitCsv(line_);
        if (f.size() < 16)
            Fail(lineno,
                 "EPW data line has " + std::to_string(f.size()) + " fields, expected at least 16");
        int year, hour, minute = 60;
        double dni, dhi;
        r->line = lineno;
        if (!ParseInt(Trim(f[0]), &year) || !ParseInt(Trim(f[1]), &r->month) ||
            !ParseInt(Trim(f[2]), &r->day) || !ParseInt(Trim(f[3]), &hour))
            Fail(lineno, "non-numeric date or hour field");
        if (hour < 1 || hour > 24) Fail(lineno, "hour " + std::to_string(hour) + " is not 1..24");
        if (!ParseNumber(Trim(f[14]), &dni))
            Fail(lineno, "non-numeric direct normal irradiance (field 15) '" + f[14] + "'");
        if (!ParseNumber(Trim(f[15]), &dhi))
            Fail(lineno, "non-numeric diffuse horizontal irradiance (field 16) '" + f[15] + "'");
        if (dni >= 9999) Fail(lineno, "direct normal irradiance (field 15) is missing (9999)");
        if (dhi >= 9999) Fail(lineno, "diffuse horizontal irradiance (field 16) is missing (9999)");
        const int interval = 60 / header_.records_per_hour;
        if (header_.records_per_hour == 1) {
            r->hour = hour - 0.5;  // the middle of the hour that ends at `hour`
        } else {
            if (!ParseInt(Trim(f[4]), &minute) || minute < 0 || minute > 60)
                Fail(lineno, "bad minute field '" + f[4] + "'");
            if (minute == 0) minute = 60;
            r->hour = hour - 1 + minute / 60.0 - interval * (0.5 / 60);
        }
        // epw2wea writes whole W/m2 (printf "%.0f" of the float values); so do we.
        r->dir = std::nearbyint(static_cast<double>(static_cast<float>(dni)));
        r->dif = std::nearbyint(static_cast<double>(static_cast<float>(dhi)));
        Check(*r);
        return true;
    }
}

bool WeatherReader::Next(WeatherRecord *r) { return epw_ ? NextEpw(r) : NextWea(r); }

}  // namespace dayflux
