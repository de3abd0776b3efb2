#include "scene/patterns.h"

#include "util/raypath.h"

namespace dayflux {

PatternFunction::PatternFunction(const Primitive &p)
    : cx_(std::make_unique<cal::Context>()), args_(p.fargs) {
    const bool colour = p.type == "colorfunc";
    if (!colour && p.type != "brightfunc")
        ErrorExit(&p.loc, p.type + " '" + p.name + "' is not a function pattern");
    const size_t nfunc = colour ? 3 : 1;
    if (p.sargs.size() < nfunc + 1)
        ErrorExit(&p.loc, p.type + " '" + p.name + "' needs its functions and a file");
    if (p.sargs.size() > nfunc + 1)
        ErrorExit(&p.loc, p.type + " '" + p.name +
                              "': transforms of pattern coordinates are not supported yet");
    cx_->LoadRayInit();
    const std::string &file = p.sargs[nfunc];
    if (file != ".") cx_->LoadFile(FindOnRaypath(file));
    for (size_t k = 0; k < nfunc; ++k) functions_.push_back(cx_->Compile(p.sargs[k], p.loc));
}

void PatternFunction::Evaluate(const std::vector<double> &channels, double rgb[3]) const {
    cal::ChannelArray ch(channels);
    ch.SetObjectArguments(args_);
    if (functions_.size() == 1) {
        rgb[0] = rgb[1] = rgb[2] = functions_[0].Evaluate(*cx_, &ch);
    } else {
        for (int k = 0; k < 3; ++k) rgb[k] = functions_[k].Evaluate(*cx_, &ch);
    }
}

}  // namespace dayflux
