// calcomp: a .cal text parsed into a context (after the ray variables Dx = $1 ..., as the ray
// tracers start), then the names it mentions evaluated, functions with a few arguments, each
// twice: specialised (specialise.h, where Compile() manages it) and interpreted. The two must
// give the same bits, or both report an error; a difference aborts, as a finding.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>

#include "cal/calcomp.h"
#include "fuzz_util.h"

namespace {

using dayflux::cal::Channels;
using dayflux::cal::Context;

constexpr size_t kMaxNames = 16;   // evaluations per input: a bound on the time each takes
constexpr size_t kMaxParams = 16;  // the interpreter remembers this many arguments per call
constexpr const char *kArguments[] = {".25", "-1.5", "$2", "3", "0", "1e3"};

bool IsIdStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '`'; }
bool IsIdChar(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '`';
}

// The names in text, as the parser reads them, first ones first.
std::vector<std::string> Names(std::string_view text) {
    std::vector<std::string> names;
    std::set<std::string> seen;
    for (size_t i = 0; i < text.size() && names.size() < kMaxNames;) {
        if (!IsIdStart(text[i])) {
            ++i;
            continue;
        }
        size_t end = i;
        while (end < text.size() && IsIdChar(text[end])) ++end;
        std::string name(text.substr(i, end - i));
        if (seen.insert(name).second) names.push_back(name);
        i = end;
    }
    return names;
}

// "name" for a variable, "name(a, b, ...)" for a function; empty where it is neither.
std::string CallOf(const Context &cx, const std::string &name) {
    const Context::Definition *d = cx.Find(cx.SymbolIndex(name));
    if (!d || d->params.size() > kMaxParams) return "";
    std::string call = name;
    for (size_t i = 0; i < d->params.size(); ++i)
        call += std::string(i ? ", " : "(") + kArguments[i % std::size(kArguments)];
    return d->params.empty() ? call : call + ")";
}

struct Outcome {
    bool error = false;
    double value = 0;
    bool Same(const Outcome &o) const {
        if (error || o.error) return error == o.error;
        return std::memcmp(&value, &o.value, sizeof value) == 0 ||
               (std::isnan(value) && std::isnan(o.value));
    }
};

Outcome Evaluate(const Context &cx, const std::string &call, bool specialised,
                 const Channels *channels) {
    Outcome out;
    try {
        const dayflux::FileLoc loc{"fuzz call", 1};
        const dayflux::cal::Expression e =
            specialised ? cx.Compile(call, loc) : cx.CompileInterpreted(call, loc);
        out.value = e.Evaluate(cx, channels);
    } catch (const dayflux::UserError &) {
        out.error = true;
    }
    return out;
}

void Compare(const Context &cx, const std::string &call, const Channels *channels) {
    const Outcome fast = Evaluate(cx, call, true, channels);
    const Outcome slow = Evaluate(cx, call, false, channels);
    if (fast.Same(slow)) return;
    std::fprintf(stderr, "calcomp: '%s' %s: specialised %s %.17g, interpreted %s %.17g\n",
                 call.c_str(), channels ? "with a ray" : "without a ray",
                 fast.error ? "error" : "=", fast.value, slow.error ? "error" : "=", slow.value);
    std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string_view text = dayflux::fuzz::AsText(data, size);
    Context cx;
    cx.DefineRayVariables();
    // Definitions before a syntax error stay in the context: evaluate those too.
    dayflux::fuzz::ExpectUserErrors([&] { cx.Load(text, dayflux::FileLoc{"fuzz.cal", 1}); });
    dayflux::cal::ChannelArray ray(
        {.1, -.2, .97, 0, 0, 1, 1.5, 2.5, .8, 3, .97, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1});
    ray.SetObjectArguments({2, .5, -1});
    for (const std::string &name : Names(text)) {
        const std::string call = CallOf(cx, name);
        if (call.empty()) continue;
        Compare(cx, call, &ray);
        Compare(cx, call, nullptr);
    }
    return 0;
}
