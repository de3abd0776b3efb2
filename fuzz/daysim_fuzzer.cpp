// DAYSIM's text inputs, each input read as all three: a project file (.hea, ReadDaysimProject,
// and where it holds a site the suns and skies ds_illum makes from it: DaysimDirectSuns,
// DaysimSkyModel over a year of steps), a sensor file (CountSensors) and a .dc file
// (ReadDaysimDc, two sensors of 150 columns). The readers take paths, so each input is written
// to a scratch file.
#include <cmath>

#include "daysim/ds_illum.h"
#include "daysim/project.h"
#include "daysim/suns.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static dayflux::fuzz::ScratchFile file;
    const std::string &path = file.Write(dayflux::fuzz::AsText(data, size));
    dayflux::fuzz::ExpectUserErrors([&] {
        const dayflux::DaysimProject p = dayflux::ReadDaysimProject(path);
        if (!p.latitude || !p.longitude || !p.time_zone) return;
        const auto suns = dayflux::DaysimDirectSuns(*p.latitude * (M_PI / 180.), false);
        const dayflux::DaysimSkyModel sky(p, 148 + static_cast<int>(suns.suns.size()));
        for (int month = 1; month <= 12; ++month)
            for (double hour = 0.5; hour < 24; hour += 2)
                sky.Step(month, 21, hour, 400 + 20 * month, 90 + 5 * month);
    });
    dayflux::fuzz::ExpectUserErrors([&] { dayflux::CountSensors(path); });
    dayflux::fuzz::ExpectUserErrors([&] { dayflux::ReadDaysimDc(path, 2, 150); });
    return 0;
}
