// epw2wea: EnergyPlus weather to the DAYSIM/RADIANCE .wea format, as RADIANCE's epw2wea writes it.
//   epw2wea file.epw [file.wea]   (without an output file the .wea goes to stdout)
#include <cmath>
#include <cstdio>
#include <string>

#include "sky/weather.h"
#include "util/errors.h"

namespace dayflux {
namespace {

int Main(int argc, char **argv) {
    if (argc < 2 || argc > 3)
        ErrorExit(std::string("Usage: ") + argv[0] + " file-name.epw [file-name.wea]");
    WeatherReader epw(argv[1]);
    if (!epw.IsEpw())
        ErrorExit(std::string(argv[1]) +
                  ": this does not seem to be an epw file (no LOCATION line)");
    const WeatherHeader &h = epw.Header();
    char buf[256];
    std::string head = "place " + h.place + "\n" + "latitude " + h.epw_latitude_text + "\n";
    std::snprintf(buf, sizeof buf, "longitude %.2f\n", h.longitude);
    head += buf;
    // RADIANCE truncates the time zone to whole hours (atoi); fractional zones keep their minutes.
    const double tz = h.epw_time_zone_hours;
    if (tz == std::trunc(tz))
        std::snprintf(buf, sizeof buf, "time_zone %.0f\n", -15.0 * tz);
    else
        std::snprintf(buf, sizeof buf, "time_zone %.2f\n", -15.0 * tz);
    std::string tz_line = buf;
    std::string tail = "site_elevation " + h.elevation_text + "\nweather_data_file_units 1\n";
    std::string text = head + tz_line + tail;
    WeatherRecord r;
    while (epw.Next(&r)) {
        std::snprintf(buf, sizeof buf, "%d %d %.3f %.0f %.0f\n", r.month, r.day, r.hour, r.dir,
                      r.dif);
        text += buf;
    }
    OutputFile out(argc == 3 ? argv[2] : "-");
    out.Write(text);
    out.Commit();
    if (argc == 3) {
        // RADIANCE 5.4 repeats the site lines on stdout when it writes a file.
        std::snprintf(buf, sizeof buf, "time_zone %.2f\n", -15.0 * tz);
        std::fputs((head + buf + tail).c_str(), stdout);
    }
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
