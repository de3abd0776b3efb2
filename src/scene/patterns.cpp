#include "scene/patterns.h"

#include <sstream>

#include "cal/glsl.h"
#include "util/raypath.h"

namespace dayflux {

PatternFunction::PatternFunction(const Primitive &p) : pattern_(p), args_(p.fargs) {
    const bool colour = p.type == "colorfunc";
    if (!colour && p.type != "brightfunc")
        ErrorExit(&p.loc, p.type + " '" + p.name + "' is not a function pattern");
    const size_t nfunc = colour ? 3 : 1;
    if (p.sargs.size() < nfunc + 1)
        ErrorExit(&p.loc, p.type + " '" + p.name + "' needs its functions and a file");
    if (p.sargs.size() > nfunc + 1)
        ErrorExit(&p.loc, p.type + " '" + p.name +
                              "': transforms of pattern coordinates are not supported yet");
    states_.local() = Load();  // errors in the files show here, on the calling thread
}

PatternFunction::State PatternFunction::Load() const {
    const Primitive &p = pattern_;
    const size_t nfunc = p.type == "colorfunc" ? 3 : 1;
    State st;
    st.cx = std::make_unique<cal::Context>();
    st.cx->LoadRayInit();
    const std::string &file = p.sargs[nfunc];
    if (file != ".") st.cx->LoadFile(FindOnRaypath(file));
    for (size_t k = 0; k < nfunc; ++k) st.functions.push_back(st.cx->Compile(p.sargs[k], p.loc));
    return st;
}

void PatternFunction::Evaluate(std::span<const double> channels, double rgb[3]) const {
    State &st = states_.local();
    if (!st.cx) st = Load();
    const cal::ChannelView ch(channels, &args_);
    if (st.functions.size() == 1) {
        rgb[0] = rgb[1] = rgb[2] = st.functions[0].Evaluate(*st.cx, &ch);
    } else {
        for (int k = 0; k < 3; ++k) rgb[k] = st.functions[k].Evaluate(*st.cx, &ch);
    }
}

std::string PatternFunction::Glsl(const std::string &name, cal::GlslPrecision precision) const {
    const State st = Load();
    std::vector<cal::GlslEntry> entries;
    for (size_t k = 0; k < st.functions.size(); ++k)
        entries.push_back({name + "_f" + std::to_string(k), &st.functions[k]});
    cal::GlslOptions o;
    o.precision = precision;
    o.prefix = name + "_d";
    o.preamble = false;
    if (args_.size() > static_cast<size_t>(o.max_args))
        ErrorExit(&pattern_.loc, "'" + pattern_.name + "': more than " +
                                     std::to_string(o.max_args) + " arguments for the GPU");
    const bool single = precision == cal::GlslPrecision::kFloat;
    const char *suffix = single ? "" : "LF";
    std::ostringstream s;
    s << cal::GenerateGlsl(*st.cx, entries, o);
    s << "void " << name << "_args() {\n    cal_arg[0] = " << args_.size() << ".0" << suffix
      << ";\n";
    s.precision(single ? 8 : 17);
    for (size_t a = 0; a < args_.size(); ++a)
        s << "    cal_arg[" << a + 1 << "] = " << std::scientific << args_[a] << suffix << ";\n";
    s << "}\n"
      << (single ? "vec3 " : "dvec3 ") << name << "() {\n    " << name << "_args();\n    return "
      << (single ? "vec3(" : "dvec3(");
    for (size_t k = 0; k < st.functions.size(); ++k)
        s << (k ? ", " : "") << name << "_f" << k << "()";
    s << ");\n}\n";
    return s.str();
}

}  // namespace dayflux
