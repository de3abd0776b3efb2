#include "scene/binary.h"

#include <cmath>

#include "scene/reader.h"

namespace dayflux {

void RadianceBinaryInput::Fail(const std::string &msg) const {
    FileLoc loc{in_.Name(), 0};
    ErrorExit(&loc, msg);
}

std::string RadianceBinaryInput::Header(const std::string &format) {
    std::string line, rest;
    bool found = false;
    if (!in_.ReadLine(&line) || line.rfind("#?", 0) != 0)
        Fail("not a RADIANCE " + what_ + " (no header)");
    std::string other;
    bool ended = false;
    while (in_.ReadLine(&line)) {
        if (line.empty()) {
            ended = true;
            break;
        }
        if (line == "FORMAT=" + format)
            found = true;
        else if (line.rfind("FORMAT=", 0) == 0)
            other = line;
        else
            rest += line + "\n";
    }
    if (!found && !other.empty()) Fail("not a RADIANCE " + what_ + " (" + other + ")");
    if (!ended) Fail("truncated " + what_ + " (in its header)");
    if (!found) Fail("not a RADIANCE " + what_ + " (no FORMAT=" + format + " in header)");
    return rest;
}

int RadianceBinaryInput::Byte() {
    const int c = in_.Get();
    if (c < 0) Fail("truncated " + what_);
    return c;
}

long RadianceBinaryInput::Int(int n) {
    long r = Byte();
    if (r & 0x80) r |= -256L;
    while (--n > 0) r = (r << 8) | Byte();
    return r;
}

std::string RadianceBinaryInput::String() {
    std::string s;
    for (int c; (c = Byte()) != 0;) s.push_back(static_cast<char>(c));
    return s;
}

double RadianceBinaryInput::Real() {
    const long l = Int(4);
    if (l == 0) {
        Byte();  // exactly zero: the exponent byte is ignored
        return 0.0;
    }
    return std::ldexp((l + .5 - (l < 0)) * (1. / 0x7fffffff), static_cast<int>(Int(1)));
}

void RadianceBinaryInput::SkipTree(int objsize, int depth) {
    // oconv's resolution limits real trees to a few dozen levels; the bound keeps a damaged or
    // hostile file from exhausting the stack.
    constexpr int kMaxTreeDepth = 128;
    if (depth > kMaxTreeDepth) Fail("damaged " + what_ + " (tree deeper than 128 levels)");
    switch (Byte()) {
        case 0:
            return;  // empty
        case 1: {    // a set of objects
            const long n = Int(objsize);
            for (long i = 0; i < n * objsize; ++i) Byte();
            return;
        }
        case 2:  // eight children
            for (int i = 0; i < 8; ++i) SkipTree(objsize, depth + 1);
            return;
        default:
            Fail("damaged " + what_);
    }
}

long RadianceBinaryInput::Objects(int objsize, Scene *scene) {
    const size_t first = scene->objects.size();
    std::vector<const PrimitiveType *> types;
    for (std::string t; !(t = String()).empty();) types.push_back(FindPrimitiveType(t));
    for (;;) {
        const long ti = Int(1);
        if (ti == -1) break;
        if (ti < 0 || ti >= static_cast<long>(types.size()) || !types[ti])
            Fail("reference to unknown type");
        Primitive p;
        p.info = types[ti];
        p.type = p.info->name;
        const long mod = Int(objsize);
        p.modifier = mod == -1 ? -1 : static_cast<int>(first + mod);
        if (p.modifier >= static_cast<int>(scene->objects.size()))
            Fail("modifier refers to a later object");
        p.modifier_name = p.modifier < 0 ? "void" : scene->objects[p.modifier].name;
        p.name = String();
        for (long n = Int(2); n > 0; --n) p.sargs.push_back(String());
        for (long n = Int(2); n > 0; --n) p.fargs.push_back(Real());
        p.loc = FileLoc{in_.Name(), 0};
        CheckArguments(p);
        scene->objects.push_back(std::move(p));
    }
    return static_cast<long>(scene->objects.size() - first);
}

void RadianceBinaryOutput::Int(long value, int nbytes) {
    char big_endian[8];
    for (int i = nbytes; i-- > 0; value >>= 8) big_endian[i] = static_cast<char>(value & 0xff);
    bytes_.append(big_endian, static_cast<size_t>(nbytes));
    if (sink_ && bytes_.size() >= kChunk) Flush();
}

void RadianceBinaryOutput::String(const std::string &s) {
    bytes_ += s;
    Byte(0);  // (flushes)
}

void RadianceBinaryOutput::Real(double value) {
    int e;
    long m = static_cast<long>(std::frexp(value, &e) * 0x7fffffff);
    if (e > 127) {
        m = m > 0 ? 0x7fffffffL : -0x7fffffffL;
        e = 127;
    } else if (e < -128) {
        m = 0;
        e = 0;
    }
    Int(m, 4);
    Int(e, 1);
}

}  // namespace dayflux
