// Issue 20's classes of bad input, through the programs: each gets a message naming where and
// what, and an exit status of 1 (never an abort or a crash); the likely mistakes RADIANCE takes
// silently get a warning or an error before any tracing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "test_util.h"

namespace dayflux::test {
namespace {

const char *const kRoom = kFloorUnderSky;

CommandResult Rcontrib(const TempDir &tmp, const std::string &rays, const std::string &args) {
    WriteFile(tmp.path() / "room.rad", kRoom);
    WriteFile(tmp.path() / "rays", rays);
    return RunCommand("rcontrib-gpu -h " + args + " room.rad < rays", tmp.path());
}

// One bad line of a long run stops it with its number, before the engine (Embree asserts on
// such rays).
TEST(Hardening, RaysThatAreNotNumbersOrBeyondAnySceneAreRefused) {
    TempDir tmp;
    for (const auto &[line, said] :
         {std::pair{"0 0 nan 0 0 1", "input ray 2: origin value nan is not a number"},
          std::pair{"0 0 0 0 inf 1", "input ray 2: direction value inf is not a number"},
          std::pair{"1e20 0 0 0 0 1", "input ray 2: origin value 1e+20 is out of range"}}) {
        const CommandResult r = Rcontrib(tmp, std::string("0 0 0 0 0 1\n") + line + "\n", "-m sky");
        EXPECT_EQ(r.status, 1) << line;
        EXPECT_NE(r.err.find(said), std::string::npos) << r.err;
    }
}

// Commands in data files run, as in RADIANCE, unless -no_commands refuses them (for services
// that open files they did not write): in scene files, in rfluxmtx's sender and receiver files,
// and in the file list of an unfrozen octree; in-process xform stays allowed.
TEST(Hardening, CommandsInDataFilesCanBeRefused) {
    TempDir tmp;
    WriteFile(tmp.path() / "room.rad", kRoom);
    WriteFile(tmp.path() / "rays", "0 0 0 0 0 1\n");
    WriteFile(tmp.path() / "floor.rad", "!echo void plastic red 0 0 5 1 0 0 0 0 && touch ran\n");
    WriteFile(tmp.path() / "moved.rad", "!xform -t 0 0 -2 room.rad\n");
    EXPECT_EQ(RunCommand("rcontrib-gpu -h -m sky room.rad floor.rad < rays", tmp.path()).status, 0);
    EXPECT_TRUE(std::filesystem::exists(tmp.path() / "ran"));
    std::filesystem::remove(tmp.path() / "ran");
    CommandResult r =
        RunCommand("rcontrib-gpu -no_commands -h -m sky room.rad floor.rad < rays", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("floor.rad:1: '!echo void plastic red 0 0 5 1 0 0 0 0 && touch ran': "
                         "commands in data files are refused (-no_commands)"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(std::filesystem::exists(tmp.path() / "ran"));
    r = RunCommand("rcontrib-gpu -no_commands -h -m sky moved.rad < rays", tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    // rfluxmtx: a receiver made by a command.
    WriteFile(tmp.path() / "sender.rad",
              "#@rfluxmtx h=u u=+Y\nvoid polygon w 0 0 12 0 0 0 0 1 0 1 1 0 1 0 0\n");
    WriteFile(tmp.path() / "sky.rad", "!cat room.rad; touch ran\n");
    r = RunCommand("rfluxmtx-gpu -no_commands -c 4 sender.rad sky.rad", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("sky.rad:1: '!cat room.rad; touch ran': commands in data files"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(std::filesystem::exists(tmp.path() / "ran"));
    // An unfrozen octree whose file list names a command (oconv records "!command" inputs so):
    // the tutorial room's, its first file made "!cat materials.rad" (the list is a run of
    // NUL-terminated names, so the rest of the octree reads as before).
    std::string oct = ReadFile(DataDir() / "scene" / "room2ph.oct");
    const size_t at = oct.find(std::string("materials.rad\0", 14), oct.find("\n\n"));
    ASSERT_NE(at, std::string::npos);
    oct.replace(at, 13, "!cat materials.rad");
    WriteFile(tmp.path() / "listed.oct", oct);
    const std::filesystem::path room = DataDir() / "scene" / "models" / "room";
    const std::string rays = " < '" + (tmp.path() / "rays").string() + "'";
    const std::string listed = " -h -m skyglow '" + (tmp.path() / "listed.oct").string() + "'";
    r = RunCommand("rcontrib-gpu" + listed + rays, room);
    EXPECT_EQ(r.status, 0) << r.err;
    r = RunCommand("rcontrib-gpu -no_commands" + listed + rays, room);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("listed.oct: '!cat materials.rad': commands in data files are refused"),
              std::string::npos)
        << r.err;
}

// -ff on a points file written as text: RADIANCE traces the garbage without a word.
TEST(Hardening, TextRaysReadAsBinaryAreWarnedOf) {
    TempDir tmp;
    const std::string warning = "the input rays look like text, but -ff reads them as binary";
    const CommandResult text = Rcontrib(tmp, "0 0 0 0 0 1\n1.5 2 -3 0 0 1\n", "-ff -m sky");
    EXPECT_NE(text.err.find(warning), std::string::npos) << text.err;
    const float ray[6] = {0, 0, 0, 0, 0, 1};
    const CommandResult binary =
        Rcontrib(tmp, std::string(reinterpret_cast<const char *>(ray), sizeof ray), "-ff -m sky");
    EXPECT_EQ(binary.status, 0) << binary.err;
    EXPECT_EQ(binary.err.find(warning), std::string::npos) << binary.err;
}

// A -m no surface uses (a misspelt or renamed modifier) gives zeros in RADIANCE, silently.
TEST(Hardening, ModifierNoSurfaceUsesIsWarnedOf) {
    TempDir tmp;
    const CommandResult r = Rcontrib(tmp, "0 0 0 0 0 1\n", "-m sky -m skye");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("warning - modifier 'skye' (-m) is used by no surface in the scene"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("'sky' (-m)"), std::string::npos) << r.err;
}

// An undefined name in a bin expression is an error before tracing, even where no ray would
// ever evaluate it (here the only ray looks down, away from the sky).
TEST(Hardening, UndefinedBinVariableStopsTheRunBeforeTracing) {
    TempDir tmp;
    const CommandResult r = Rcontrib(tmp, "0 0 0 0 0 -1\n", "-ab 0 -b 'if(Dz,skybin,0)' -m sky");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("-b if(Dz,skybin,0) (modifier 'sky'): undefined variable 'skybin'"),
              std::string::npos)
        << r.err;
}

// Matrix headers that promise more than the input holds, or rows beyond memory: a message at
// once, not an abort (std::length_error) or gigabytes allocated first.
TEST(Hardening, MatrixSizesBeyondTheirDataAreRefused) {
    TempDir tmp;
    const std::string head = "#?RADIANCE\nNCOMP=3\nFORMAT=float\n";
    WriteFile(tmp.path() / "tall.fmx",
              head + "NROWS=2000000000\nNCOLS=3\n\n" + std::string(36, 'x'));
    WriteFile(tmp.path() / "wide.fmx", head + "NROWS=2\nNCOLS=2000000000\n\n");
    WriteFile(tmp.path() / "huge.fmx", head + "NROWS=2000000000\nNCOLS=2000000000\n\n");
    for (const auto &[file, said] :
         {std::pair{"tall.fmx", "tall.fmx: unexpected end of input in row 2 of 2000000000"},
          std::pair{"wide.fmx",
                    "wide.fmx: 2000000000 columns of 3 components: rows of more than "
                    "134217728 values are not supported"},
          std::pair{"huge.fmx", "huge.fmx: 2000000000 columns"}}) {
        for (const char *program : {"rmtxop", "dctimestep"}) {
            const CommandResult r =
                RunCommand(std::string(program) + " " + file + " " + file, tmp.path());
            EXPECT_EQ(r.status, 1) << program << " " << file;
            EXPECT_NE(r.err.find(said), std::string::npos) << program << ": " << r.err;
        }
    }
}

// A spike in the weather (10^6 W/m2 of diffuse light) is refused with its line, instead of
// NaN patches and negative skies.
TEST(Hardening, WeatherBeyondWhatTheSunGivesIsRefused) {
    TempDir tmp;
    WriteFile(tmp.path() / "spike.wea",
              "place here\nlatitude 40.78\nlongitude 73.96\ntime_zone 75\nsite_elevation 40\n"
              "weather_data_file_units 1\n6 21 12.5 800 200\n6 21 13.5 100 1000000\n");
    const CommandResult r = RunCommand("gendaymtx -m 1 spike.wea", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("spike.wea:8: 100 W/m2 direct, 1e+06 W/m2 diffuse: more than the sun "
                         "can give (at most 1500 W/m2)"),
              std::string::npos)
        << r.err;
}

// gendaymtx holds every time step until it writes the rows: more than -max_steps (5000000 by
// default, about 2 GB) is refused at the first step beyond, naming its line, before memory runs
// out; -u counts only the steps it keeps.
TEST(Hardening, TimeStepsBeyondTheCapAreRefused) {
    TempDir tmp;
    WriteFile(tmp.path() / "three.wea",
              "place here\nlatitude 40.78\nlongitude 73.96\ntime_zone 75\nsite_elevation 40\n"
              "weather_data_file_units 1\n6 21 0.5 0 0\n6 21 12.5 800 200\n6 21 13.5 700 150\n");
    CommandResult r = RunCommand("gendaymtx -m 1 -max_steps 2 three.wea", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("three.wea:9: more than 2 time steps (-max_steps)"), std::string::npos)
        << r.err;
    EXPECT_TRUE(r.out.empty());
    r = RunCommand("gendaymtx -m 1 -u -max_steps 2 three.wea", tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("NCOLS=2"), std::string::npos);
    r = RunCommand("gendaymtx -m 1 -max_steps 0 three.wea", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("-max_steps needs a whole number"), std::string::npos) << r.err;
}

// Issue 41: an output naming a FIFO, a device or a symbolic link was renamed over, replacing the
// node (as root, /dev/null for the whole system). The programs now write into it: the reader of
// a FIFO gets the records, a device node (/dev/null's, made here) stays, a link is written
// through as RADIANCE writes it.
TEST(Hardening, OutputsThatAreNotRegularFilesAreWrittenNotReplaced) {
    TempDir tmp;
    WriteFile(tmp.path() / "three.wea",
              "place here\nlatitude 40.78\nlongitude 73.96\ntime_zone 75\nsite_elevation 40\n"
              "weather_data_file_units 1\n6 21 12.5 800 200\n6 21 13.5 700 150\n");
    CommandResult r =
        RunCommand("gendaymtx -m 1 -D suns -M mods three.wea > /dev/null", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string suns = ReadFile(tmp.path() / "suns");
    ASSERT_NE(suns.find("solar"), std::string::npos);
    // A FIFO with its reader (which would wait for ever on a replaced FIFO).
    r = RunCommand(
        "mkfifo fifo && { timeout 60 cat fifo > got & } && "
        "gendaymtx -m 1 -D fifo three.wea > /dev/null && wait && test -p fifo",
        tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(ReadFile(tmp.path() / "got"), suns);
    // A symbolic link: written through, the link kept.
    WriteFile(tmp.path() / "room.rad", kRoom);
    WriteFile(tmp.path() / "rays", "0 0 0 0 0 1\n");
    r = RunCommand(
        "mkdir data && ln -s data/real link && "
        "rcontrib-gpu -h -fo -o link -m sky room.rad < rays && test -L link",
        tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(ReadFile(tmp.path() / "data" / "real"),
              "1.000000e+00\t1.000000e+00\t1.000000e+00\t\n");
    if (geteuid() != 0) GTEST_SKIP() << "mknod of a character device needs root";
    r = RunCommand(
        "mknod null c 1 3 && gendaymtx -m 1 -D null three.wea > /dev/null && "
        "test \"$(stat -c %F:%t,%T null)\" = 'character special file:1,3'",
        tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
}

// Issue 41: a `source` whose material gives no light was shaded at infinity (a NaN ray, Embree's
// assertion) or read a pattern it did not have (SIGSEGV). RADIANCE leaves such a source out of
// its light sources; written so, it is a mistake, refused with its line by every program that
// traces (one scene reader, one table of materials). A void source is skipped, as in RADIANCE.
TEST(Hardening, SourceWhoseMaterialGivesNoLightIsRefused) {
    TempDir tmp;
    WriteFile(tmp.path() / "rays", "0 0 0 0 0 1\n");
    for (const auto &[material, said] :
         {std::pair{"void plastic m 0 0 5 .5 .5 .5 0 0", "plastic 'm'"},
          std::pair{"void glass m 0 0 3 .9 .9 .9", "glass 'm'"},
          std::pair{"void glow a 0 0 4 1 1 1 0\nvoid glow b 0 0 4 2 2 2 0\n"
                    "void mixfunc m 4 a b Dx . 0 0",
                    "mixfunc 'm'"}}) {
        WriteFile(tmp.path() / "sky.rad", std::string(material) +
                                              "\nm source dome 0 0 4 0 0 1 180\n"
                                              "void glow sky 0 0 4 1 1 1 0\n");
        const std::string line =
            std::to_string(std::count(material, material + std::strlen(material), '\n') + 2);
        for (const char *program :
             {"rcontrib-gpu -h -m sky", "rtrace_dc-gpu -h -ab 1 -N 148 -Dd"}) {
            const CommandResult r =
                RunCommand(std::string(program) + " sky.rad < rays", tmp.path());
            EXPECT_EQ(r.status, 1) << program << " " << material;
            EXPECT_NE(r.err.find("sky.rad:" + line + ": source 'dome': its material is " + said +
                                 ", which gives no light"),
                      std::string::npos)
                << program << ": " << r.err;
        }
    }
    WriteFile(tmp.path() / "sky.rad",
              "void source nothing 0 0 4 0 0 1 180\nvoid glow sky 0 0 4 1 1 1 0\n"
              "sky source dome 0 0 4 0 0 1 180\n");
    const CommandResult r = RunCommand("rcontrib-gpu -h -m sky sky.rad < rays", tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "1.000000e+00\t1.000000e+00\t1.000000e+00\t\n");
}

// Issue 41: options cast to integers unchecked (UBSan): a negative seed, and bin counts beyond
// the int range, directly or through reinhart.cal's Nrbins at MF:1000000; and values the GPU's
// options do not know. Each is refused with the option named, before the scene is read.
TEST(Hardening, OptionsBeyondTheirRangeAreRefused) {
    TempDir tmp;
    for (const auto &[options, said] :
         {std::pair{"-seed -1 -m sky", "-seed -1: a whole number from 0 to 18446744073709551615"},
          std::pair{"-seed 2.5 -m sky", "-seed 2.5: a whole number"},
          std::pair{"-bn 1e14 -m sky", "-bn 1e14: bin count 1e+14 is above 268435456"},
          std::pair{"-e MF:1000000 -f reinhart.cal -b rbin -bn Nrbins -m sky",
                    "-bn Nrbins: bin count 1.44e+14 is above 268435456"},
          std::pair{"-bn '1e308*10 - 1e308*10' -m sky", "is below 1"},
          std::pair{"-bn 2e8 -m sky -m grey",
                    "the modifiers' bins, 400000000 by 'grey', are "
                    "above 268435456"},
          std::pair{"-gpu_accum half -m sky", "-gpu_accum half: pair, float or double"},
          std::pair{"-gpu_cal half -m sky", "-gpu_cal half: float or double"},
          std::pair{"-gpu_spirv_opt fast -m sky",
                    "-gpu_spirv_opt fast: auto, performance, size or none"},
          std::pair{"-gpu_engine rays -m sky", "-gpu_engine rays: tasks or paths"},
          std::pair{"-gpu_waves 20000 -m sky", "-gpu_waves: a whole number from 0 to 10000"}}) {
        const CommandResult r = Rcontrib(tmp, "0 0 0 0 0 1\n", options);
        EXPECT_EQ(r.status, 1) << options;
        EXPECT_NE(r.err.find(said), std::string::npos) << options << ": " << r.err;
    }
    const CommandResult r = Rcontrib(tmp, "0 0 0 0 0 1\n", "-seed 18446744073709551615 -m sky");
    EXPECT_EQ(r.status, 0) << r.err;
}

// Issue 41: inputs that gave NaN silently. Glass below an index of 1 has no transmitted cosine at
// grazing angles (-nan coefficients, exit 0) and is refused with its line; a dielectric's index
// must be above 0; gendaymtx -r nan made a NaN sky.
TEST(Hardening, InputsThatGaveNanAreRefused) {
    TempDir tmp;
    for (const auto &[material, said] :
         {std::pair{"void glass g 0 0 4 .9 .9 .9 .5",
                    "scene.rad:1: glass 'g': refractive index "
                    "0.5 is below 1"},
          std::pair{"void dielectric g 0 0 5 .9 .9 .9 -1 0",
                    "scene.rad:1: dielectric 'g': refractive index -1 is not above 0"}}) {
        WriteFile(tmp.path() / "scene.rad",
                  std::string(material) + "\ng polygon p 0 0 12 -1 -1 1 1 -1 1 1 1 1.5 -1 1 1.5\n");
        const CommandResult r = Rcontrib(tmp, "0 0 0 0 .3 1\n", "-ab 1 -m sky scene.rad");
        EXPECT_EQ(r.status, 1) << material;
        EXPECT_NE(r.err.find(said), std::string::npos) << r.err;
    }
    WriteFile(tmp.path() / "one.wea",
              "place here\nlatitude 40.78\nlongitude 73.96\ntime_zone 75\nsite_elevation 40\n"
              "weather_data_file_units 1\n6 21 12.5 800 200\n");
    const CommandResult r = RunCommand("gendaymtx -m 1 -r nan one.wea", tmp.path());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("-r: 'nan' is not a finite number"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty());
}

// Issue 41: with weather_data_file_units 2 the direct value is on the horizontal, and gendaymtx
// divides it by the sine of the solar altitude; a sun just above the horizon (66.6 N, 1 January,
// 0.07 degrees) made 20 W/m2 into 16000 W/m2 normal to it, and the Perez sky NaN in most
// patches (RADIANCE's too). Where the sky comes out NaN (only there: real units-2 weather such
// as frads' keeps RADIANCE's skies), the derived value is capped at what the sun gives, with a
// warning that counts the steps; the sky is finite and the sun's horizontal share stays 20 W/m2
// within the cap's few percent.
TEST(Hardening, DirectOnTheHorizontalAtSunriseGivesAFiniteSky) {
    TempDir tmp;
    WriteFile(tmp.path() / "polar.wea",
              "place polar\nlatitude 66.6\nlongitude 0\ntime_zone 0\nsite_elevation 0\n"
              "weather_data_file_units 2\n1 1 11.4 20 100\n1 1 11.4 1400 100\n"
              "1 1 12 5 50\n");
    const CommandResult r = RunCommand("gendaymtx -h -m 1 polar.wea", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(
        r.err.find(
            "polar.wea:7: 20 W/m2 direct on the horizontal at a solar altitude of "
            "0.0729 degrees is more than the sun gives normal to it, and made the sky NaN (as "
            "RADIANCE's): taken as 1500 W/m2 (2 time steps)"),
        std::string::npos)
        << r.err;
    std::istringstream ss(r.out);
    int values = 0, positive = 0;
    for (std::string w; ss >> w; ++values) {
        char *end = nullptr;
        const double v = std::strtod(w.c_str(), &end);
        ASSERT_EQ(*end, '\0') << w;
        ASSERT_TRUE(std::isfinite(v)) << "entry " << values << ": " << w;
        positive += v > 0;
    }
    EXPECT_EQ(values, 146 * 3 * 3);
    EXPECT_GT(positive, 100);
}

// Issue 41's end-to-end fuzz target (fuzz/engine_fuzzer.cpp) found these; its corpus replays
// them, and here is what each now gives. A negative -lw made the hemisphere's sample count the
// root of a negative number; a direction of 1e-300 a NaN direction in float (Embree's assertion:
// RADIANCE's normalize() finds it zero, a flush, and so do we); a roughness of 1e30 a square
// beyond float; a tracked antimatter with -V+ read its inside counters as a pattern.
TEST(Hardening, WhatTheEngineFuzzerFoundIsHandled) {
    TempDir tmp;
    CommandResult r = Rcontrib(tmp, "0 0 0 0 0 1\n", "-ab 1 -lw -1 -m sky");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("-lw -1: a weight of 0 or more"), std::string::npos) << r.err;
    // the tiny direction: a zero ray, between two ordinary ones (-c 1: three records)
    r = Rcontrib(tmp, "0 0 0 0 0 1\n0 0 0 1e-300 0 1e-300\n0 0 0 0 0 1e-20\n", "-ab 0 -m sky");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out,
              "1.000000e+00\t1.000000e+00\t1.000000e+00\t\n"
              "0.000000e+00\t0.000000e+00\t0.000000e+00\t\n"
              "1.000000e+00\t1.000000e+00\t1.000000e+00\t\n");
    // the rough floor (above the room's): as at the cap, a roughness of 1e5
    WriteFile(tmp.path() / "rough.rad",
              "void plastic shiny 0 0 5 .5 .5 .5 .05 1e30\n"
              "shiny polygon f 0 0 12 -5 -5 -.5 5 -5 -.5 5 5 -.5 -5 5 -.5\n");
    const std::string down = "0 0 0 0 0 -1\n0 0 0 .3 0 -1\n";
    r = Rcontrib(tmp, down, "-ab 1 -ad 64 -m sky rough.rad");
    EXPECT_EQ(r.status, 0) << r.err;
    WriteFile(tmp.path() / "rough.rad",
              "void plastic shiny 0 0 5 .5 .5 .5 .05 1e5\n"
              "shiny polygon f 0 0 12 -5 -5 -.5 5 -5 -.5 5 5 -.5 -5 5 -.5\n");
    const CommandResult r3 = Rcontrib(tmp, down, "-ab 1 -ad 64 -m sky rough.rad");
    EXPECT_EQ(r.out, r3.out);
    EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
    // numbers beyond float's: a glass of index 1e300 (NaN), a BSDF 1e30 m thick (rays from
    // beyond Embree's range), a distant source of negative size
    const std::string pane = "polygon p 0 0 12 -1 -1 1 1 -1 1 1 1 1 -1 1 1";
    const std::vector<std::pair<std::string, std::string>> beyond = {
        {"void glass g 0 0 4 .9 .9 .9 1e300\ng " + pane,
         "glass 'g': refractive index 1e+300 is beyond any material's"},
        {"void BSDF b 6 1e30 " + (DataDir() / "bsdf" / "clear.xml").string() + " 0 0 1 . 0 0\nb " +
             pane,
         "BSDF 'b': thickness 1e30 is beyond any window's"},
        {"void glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 -2", "'s': zero size"}};
    for (const auto &[scene, said] : beyond) {
        WriteFile(tmp.path() / "far.rad", scene + "\n");
        r = Rcontrib(tmp, "0 0 0 0 0 1\n", "-ab 1 -ad 16 -m sky far.rad");
        EXPECT_EQ(r.status, 1) << scene;
        EXPECT_NE(r.err.find(said), std::string::npos) << r.err;
    }
    // antimatter tracked, -V+: its colour is none
    WriteFile(tmp.path() / "cut.rad",
              "void plastic slab 0 0 5 .5 .5 .5 0 0\nvoid antimatter cut 1 slab 0 0\n"
              "slab polygon top 0 0 12 -5 -5 -.5 5 -5 -.5 5 5 -.5 -5 5 -.5\n"
              "cut sphere hole 0 0 4 0 0 -.5 .2\n");
    r = Rcontrib(tmp, "0 0 0 0 0 -1\n", "-ab 1 -ad 16 -V+ -m cut -m sky cut.rad");
    EXPECT_EQ(r.status, 0) << r.err;
}

// Issue 41's fuzz target: shapes RADIANCE's readers check (o_sphere(), getcone()) went to the
// engine unchecked, a sphere of radius 0 giving NaN normals. Now as RADIANCE: a zero radius is an
// error, a negative one turns a sphere into a bubble with a warning, radii that cancel leave a
// cone out with a warning, and a ring's radii are taken in either order (inner, outer).
TEST(Hardening, ShapesAreCheckedAsRadianceChecksThem) {
    TempDir tmp;
    const auto run = [&](const std::string &shape) {
        WriteFile(tmp.path() / "shape.rad", "void plastic black 0 0 5 0 0 0 0 0\n" + shape + "\n");
        return Rcontrib(tmp, "0 0 0 0 0 1\n", "-ab 0 -m sky shape.rad");
    };
    CommandResult r = run("black sphere ball 0 0 4 0 0 2 0");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("shape.rad:2: sphere 'ball': zero radius"), std::string::npos) << r.err;
    r = run("black sphere ball 0 0 4 0 0 2 -.5");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("shape.rad:2: sphere 'ball': negative radius"), std::string::npos);
    EXPECT_EQ(r.out, "0.000000e+00\t0.000000e+00\t0.000000e+00\t\n");  // the bubble's outside
    r = run("black cone hat 0 0 8 0 0 1 0 0 2 .5 -.5");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("cone 'hat': illegal radii (left out)"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "1.000000e+00\t1.000000e+00\t1.000000e+00\t\n");
    // a lamp left out is no light source either (the fuzz target's next find: its source was
    // looked for among the shapes, and read past them)
    r = run("void light lamp 0 0 3 10 10 10\nlamp ring bulb 0 0 8 0 0 1 0 0 -1 3 -3");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("ring 'bulb': illegal radii (left out)"), std::string::npos) << r.err;
    r = run("black ring lid 0 0 8 0 0 1 0 0 -1 1 0");  // outer radius first: still a disc
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "0.000000e+00\t0.000000e+00\t0.000000e+00\t\n");
}

// Issue 41's fuzz target: an illum `source` (a distant one) passes the rays it was not aimed at
// on to its alternate, from the point at infinity where they met it: a ray from 1e30 m, which
// Embree refuses (an assertion), and without surfaces, the same source met again 200 times.
// Nothing lies beyond a distant source: the ray ends there, counted once.
TEST(Hardening, RayThroughADistantIllumEndsThere) {
    TempDir tmp;
    WriteFile(tmp.path() / "illum.rad",
              "void illum window 0 0 3 .3 .3 .1\nwindow source pane 0 0 4 0 0 1 360\n");
    WriteFile(tmp.path() / "room.rad", kRoom);
    for (const char *scene : {"illum.rad", "illum.rad room.rad"}) {
        const CommandResult r = RunCommand(
            std::string("printf '0 0 0 0 0 1\\n' | rcontrib-gpu -h -ab 1 -ad 16 -m window ") +
                scene,
            tmp.path());
        EXPECT_EQ(r.status, 0) << scene << ": " << r.err;
        EXPECT_EQ(r.out, "1.000000e+00\t1.000000e+00\t1.000000e+00\t\n") << scene;
    }
}

}  // namespace
}  // namespace dayflux::test
