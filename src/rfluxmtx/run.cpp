// rfluxmtx on dayflux's engines: RADIANCE's rfluxmtx becomes an rcontrib command, here run in
// the same process: the sender's sample rays (sender.h) go straight to the engine, or, in
// pass-through mode (sender "-"), the rays come from the standard input.
#include "rfluxmtx/run.h"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "rcontrib/options.h"
#include "rcontrib/run.h"
#include "rfluxmtx/annotations.h"
#include "rfluxmtx/command.h"
#include "rfluxmtx/sender.h"
#include "util/errors.h"

namespace dayflux {
namespace {

// The system's scene files and octrees (-i octree, as oconv takes one), then the receiver.
std::vector<std::string> SceneArguments(const RfluxmtxCommand &cmd) {
    std::vector<std::string> scene;
    for (size_t i = 0; i < cmd.system.size(); ++i) {
        const std::string &a = cmd.system[i];
        if (a == "-i" && i + 1 < cmd.system.size()) {
            scene.push_back(cmd.system[++i]);
        } else if (a.size() > 1 && a[0] == '-') {
            ErrorExit("system argument '" + a + "': scene files and -i octree only");
        } else {
            scene.push_back(a);
        }
    }
    scene.push_back(cmd.receiver);
    return scene;
}

// The words as one line; with quote_specials, a word with shell specials in single quotes (as
// rfluxmtx -v shows the rcontrib command).
std::string Joined(const std::vector<std::string> &words, bool quote_specials = false) {
    std::string line;
    for (const std::string &w : words) {
        const bool quote =
            quote_specials && w.find_first_of(" \t\"'$*?()[]{}|&;<>!`\\") != std::string::npos;
        line += (line.empty() ? "" : " ") + (quote ? "'" + w + "'" : w);
    }
    return line;
}

}  // namespace

void RunRfluxmtx(const std::vector<std::string> &args) {
    const char *const program = args.at(0).c_str();
    RfluxmtxCommand cmd = ParseRfluxmtxCommand(args);
    const std::vector<FluxGroup> receivers = ReadReceivers(cmd.receiver);
    for (const std::string &a : ReceiverArguments(receivers)) cmd.rcontrib.push_back(a);
    std::unique_ptr<FluxGroup> sender;
    std::unique_ptr<SenderSampler> sampler;
    RaySource rays;  // pass-through: the standard input
    if (!cmd.sender.empty()) {
        sender = std::make_unique<FluxGroup>(ReadSender(cmd.sender));
        sampler =
            std::make_unique<SenderSampler>(*sender, cmd.samples, cmd.seed ^ 0x9e3779b97f4a7c15u);
        cmd.rcontrib.insert(cmd.rcontrib.end(), {"-y", std::to_string(sampler->Bins())});
        rays = [&sampler](double ray[6]) { return sampler->Next(ray); };
    }
    const std::vector<std::string> scene = SceneArguments(cmd);
    std::vector<std::string> rcontrib = cmd.rcontrib;
    rcontrib.insert(rcontrib.end(), scene.begin(), scene.end());
    std::vector<std::string> header_args = {"rcontrib-gpu"};
    const RcontribOptions o = ParseRcontribOptions(rcontrib, &header_args);
    if (cmd.verbose) {
        // rfluxmtx's words: it "opens a pipe to" rcontrib when it samples, else "runs" it.
        std::fprintf(stderr, "%s: %s: %s\n", program, sampler ? "opening pipe to" : "running",
                     Joined(header_args, true).c_str());
        if (sampler) {
            const size_t elements = sender->surfaces.size();
            std::fprintf(
                stderr, "%s: sampling %d directions%s\n", program, sampler->Bins(),
                elements > 1 ? (" (" + std::to_string(elements) + " elements)").c_str() : "");
        }
    }
    RunRcontrib(o, header_args, Joined(args) + "\n", std::move(rays));
}

}  // namespace dayflux
