// Weather files read by WeatherReader: .wea headers and records (units 1, 2, 3) and EnergyPlus
// .epw (recognised by its LOCATION line) converted as epw2wea does. WeatherReader takes a path,
// so each input is written to a scratch file.
#include "fuzz_util.h"
#include "sky/weather.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static dayflux::fuzz::ScratchFile file;
    const std::string &path = file.Write(dayflux::fuzz::AsText(data, size));
    dayflux::fuzz::ExpectUserErrors([&] {
        dayflux::WeatherReader reader(path);
        dayflux::WeatherRecord record;
        while (reader.Next(&record)) {
        }
    });
    return 0;
}
