#include "rfluxmtx/command.h"

#include <cerrno>
#include <cstdlib>
#include <set>

#include "rcontrib/options.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/options.h"
#include "util/strings.h"

namespace dayflux {

namespace {

[[noreturn]] void Usage(const std::string &prog, const std::string &bad) {
    ErrorExit((bad.empty() ? "" : "unsupported option '" + bad + "'\n") + "Usage: " + prog +
              " [-v][rcontrib options] sender.rad receiver.rad [-i system.oct] [system.rad ..]");
}

// dayflux's own options with their number of values, passed to rcontrib-gpu as they are.
int OursWithValues(const std::string &a) {
    static const std::set<std::string> with_value = {"-seed", "-asub", "-se", "-first_record"};
    if (with_value.count(a) || IsEngineOption(a)) return 1;
    if (a.rfind("-progress", 0) == 0 || a == "-no_commands") return 0;
    return -1;
}

// How many words rcontrib option `a` takes with it (rfluxmtx's "na" - 1), or -1 for an option
// rfluxmtx does not pass. args[i] is a.
int RcontribValues(const std::vector<std::string> &args, size_t i) {
    const std::string &a = args[i];
    const char c = a[1], c2 = a.size() > 2 ? a[2] : '\0';
    const auto positive = [&](size_t k) {
        return k < args.size() && std::atoi(args[k].c_str()) > 0;
    };
    switch (c) {
        case 'w':
        case 'V':
        case 'u':
        case 'h':
        case 'r':
            return 0;
        case 'n':
        case 's':
        case 'o':
        case 't':
        case 'l':
            return 1;
        case 'b':
            return c2 == 'v' ? 0 : -1;
        case 'd':
            return c2 == 'v' ? 0 : 1;
        case 'a':
            if (c2 == 'p') return 1 + (positive(i + 2) ? 1 + positive(i + 3) : 0);
            return c2 == 'v' ? 3 : 1;
        case 'm':
            if (c2 == '\0') return -1;
            return c2 == 'e' || c2 == 'a' ? 3 : 1;
        default:
            return -1;
    }
}

}  // namespace

RfluxmtxCommand ParseRfluxmtxCommand(const std::vector<std::string> &argv) {
    const std::string prog = argv.empty() ? "rfluxmtx-gpu" : argv[0];
    const std::vector<std::string> args = ExpandOptionFiles(argv);
    RfluxmtxCommand cmd;
    cmd.rcontrib = {"rcontrib-gpu", "-fo+"};
    std::string format = "-faa", xres, yres, limit_distance, irradiance;
    size_t i = 0;
    for (; i + 2 < args.size(); ++i) {
        const std::string &a = args[i];
        if (a.size() < 2 || a[0] != '-') break;
        const auto need = [&](int n) {
            if (i + n >= args.size()) Usage(prog, "");
        };
        if (const int n = OursWithValues(a); n >= 0) {
            need(n + 2);
            if (a == "-seed") cmd.seed = std::strtoull(args[i + 1].c_str(), nullptr, 10);
            if (a == "-no_commands") AllowCommandsInDataFiles(false);  // before any file is read
            cmd.rcontrib.insert(cmd.rcontrib.end(), args.begin() + i, args.begin() + i + n + 1);
            i += n;
        } else if (a == "-v") {
            cmd.verbose = true;
        } else if (a[1] == 'f') {  // -fa -ff -fd -fc (output), two letters: input and output
            const std::string formats = "afdc";
            if (a.size() < 3 || a.size() > 4 || formats.find(a[2]) == std::string::npos ||
                (a.size() == 4 && formats.find(a[3]) == std::string::npos))
                Usage(prog, a);
            format[2] = a[2];
            format[3] = a.size() > 3 ? a[3] : a[2];
        } else if (a == "-x" || a == "-y") {
            need(3);
            (a == "-x" ? xres : yres) = args[++i];
        } else if (a == "-c") {
            need(3);
            // Its leading digits, as RADIANCE's atoi() reads them (2.5 and 2e3 are 2), without
            // atoi()'s undefined overflow.
            errno = 0;
            const long n = std::strtol(args[++i].c_str(), nullptr, 10);
            if (errno != 0 || n < 1 || n > 1000000000L)
                ErrorExit("-c " + args[i] + ": a positive count (at most 1e9)");
            cmd.samples = static_cast<int>(n);
        } else if (a[1] == 'i' || a[1] == 'I') {
            irradiance = a;
        } else if (a.rfind("-ld", 0) == 0) {
            limit_distance = a;
        } else {
            const int n = RcontribValues(args, i);
            if (n < 0) Usage(prog, a);
            need(n + 2);
            cmd.rcontrib.insert(cmd.rcontrib.end(), args.begin() + i, args.begin() + i + n + 1);
            i += n;
        }
    }
    if (i + 2 > args.size()) Usage(prog, "");
    cmd.sender = args[i++];
    cmd.receiver = args[i++];
    cmd.system.assign(args.begin() + i, args.end());
    if (cmd.sender == "-") {  // pass-through: rcontrib reads the rays
        cmd.sender.clear();
        if (!irradiance.empty()) cmd.rcontrib.push_back(irradiance);
        if (!xres.empty()) cmd.rcontrib.insert(cmd.rcontrib.end(), {"-x", xres});
        if (!yres.empty()) cmd.rcontrib.insert(cmd.rcontrib.end(), {"-y", yres});
        if (!limit_distance.empty()) cmd.rcontrib.push_back(limit_distance);
        if (cmd.samples <= 0) cmd.samples = 1;
    } else {
        if (cmd.sender[0] == '-') Usage(prog, cmd.sender);
        if (!irradiance.empty()) ErrorExit("-i, -I supported for pass-through only");
        for (const std::string &w : cmd.rcontrib)
            if (w == "-first_record")
                ErrorExit(
                    "-first_record shards the rays read in pass-through mode (sender -), "
                    "not a sender's samples");
        format[2] = 'd';  // the sample rays go to rcontrib as doubles
        if (cmd.samples <= 0) cmd.samples = 10000;
    }
    cmd.rcontrib.insert(cmd.rcontrib.end(), {format, "-c", std::to_string(cmd.samples)});
    return cmd;
}

std::vector<std::string> ReceiverArguments(const std::vector<FluxGroup> &receivers) {
    std::vector<std::string> out;
    std::set<std::string> loaded;  // each .cal file once, before the first receiver using it
    const auto g6 = [](double v) {
        std::string s;
        AppendGeneral(&s, v, 6);
        return s;
    };
    for (const FluxGroup &g : receivers) {
        double n[3], u[3];
        g.Normal(n);
        g.Up(u);
        const std::string sign = g.basis.left_handed ? "-1" : "+1";
        const std::string frame = "rNx=" + g6(n[0]) + ",rNy=" + g6(n[1]) + ",rNz=" + g6(n[2]) +
                                  ",Ux=" + g6(u[0]) + ",Uy=" + g6(u[1]) + ",Uz=" + g6(u[2]) +
                                  ",RHS=" + sign;
        std::string cal, params, bins, bin;
        switch (g.basis.kind) {
            case FluxBasis::kUniform:
                bin = "if(-Dx*" + g6(n[0]) + "-Dy*" + g6(n[1]) + "-Dz*" + g6(n[2]) + ",0,-1)";
                bins = "1";
                break;
            case FluxBasis::kShirleyChiu:
                if (g.basis.size <= 1)
                    ErrorExit(&g.loc,
                              "missing size for Shirley-Chiu sampling ('" + g.modifier + "')");
                cal = "disk2square.cal";
                params = "SCdim=" + std::to_string(g.basis.size) + "," + frame;
                bins = "SCdim*SCdim", bin = "scbin";
                break;
            case FluxBasis::kReinhart:
                cal = "reinhartb.cal";
                params = "MF=" + std::to_string(g.basis.size) + "," + frame;
                bins = "Nrbins", bin = "rbin";
                break;
            default: {
                const char *name = g.basis.kind == FluxBasis::kKlemsFull   ? "k"
                                   : g.basis.kind == FluxBasis::kKlemsHalf ? "kh"
                                                                           : "kq";
                cal = g.basis.kind == FluxBasis::kKlemsFull   ? "klems_full.cal"
                      : g.basis.kind == FluxBasis::kKlemsHalf ? "klems_half.cal"
                                                              : "klems_quarter.cal";
                params = "RHS=" + sign;
                bins = std::string("N") + name + "bins";
                bin = std::string(name) + "bin(" + g6(n[0]) + "," + g6(n[1]) + "," + g6(n[2]) +
                      "," + g6(u[0]) + "," + g6(u[1]) + "," + g6(u[2]) + ")";
            }
        }
        if (!g.output.empty()) out.insert(out.end(), {"-o", g.output});
        if (!cal.empty() && loaded.insert(cal).second) out.insert(out.end(), {"-f", cal});
        if (!params.empty()) out.insert(out.end(), {"-p", params});
        out.insert(out.end(), {"-bn", bins, "-b", bin, "-m", g.modifier});
    }
    return out;
}

}  // namespace dayflux
