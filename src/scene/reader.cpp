#include "scene/reader.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "scene/octree.h"
#include "util/raypath.h"
#include "util/strings.h"

namespace dayflux {

namespace {

constexpr int kMaxCommandDepth = 32;

bool IsSpace(int c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

// A word as RADIANCE's fgetword() reads it: white-space separated, or in double quotes.
bool Word(InputSource &in, std::string *w) {
    int c;
    while ((c = in.Peek()) >= 0 && IsSpace(c)) in.Get();
    if (c < 0) return false;
    w->clear();
    if (c == '"') {
        in.Get();
        while ((c = in.Get()) >= 0 && c != '"') w->push_back(static_cast<char>(c));
        return true;
    }
    while ((c = in.Peek()) >= 0 && !IsSpace(c)) w->push_back(static_cast<char>(in.Get()));
    return true;
}

}  // namespace

void SceneReader::KnowExistingModifiers() {
    for (size_t i = 0; i < scene_->objects.size(); ++i) {
        const PrimitiveKind kind = scene_->objects[i].info->kind;
        if (kind != PrimitiveKind::kSurface && kind != PrimitiveKind::kVolume)
            modifiers_[scene_->objects[i].name] = static_cast<int>(i);
    }
}

void SceneReader::ReadFile(const std::string &path) {
    auto in = InputSource::Open(path);
    Read(*in, Context{});
}

void SceneReader::Read(InputSource &in) { Read(in, Context{}); }

void SceneReader::ReadText(std::string_view text, const std::string &name) {
    auto in = InputSource::FromString(std::string(text), name);
    Read(*in, Context{});
}

void SceneReader::Read(InputSource &in, const Context &cx) {
    for (;;) {
        int c = in.Peek();
        if (c < 0) break;
        if (IsSpace(c)) {
            in.Get();
            continue;
        }
        if (c == '#') {
            std::string skip;
            in.ReadLine(&skip);
            continue;
        }
        if (c == '!') {
            FileLoc loc = in.Loc();
            std::string line, command;
            // A backslash at the end of a line continues the command.
            while (in.ReadLine(&line)) {
                if (!line.empty() && line.back() == '\\') {
                    line.pop_back();
                    command += line + " ";
                    continue;
                }
                command += line;
                break;
            }
            RunCommand(command.substr(1), loc, cx);
            continue;
        }
        ReadPrimitive(in, cx);
    }
}

void SceneReader::ReadPrimitive(InputSource &in, const Context &cx) {
    Primitive p;
    p.loc = in.Loc();
    std::string w;
    Word(in, &p.modifier_name);
    if (!Word(in, &p.type))
        ErrorExit(&p.loc, "unexpected end of input after modifier '" + p.modifier_name + "'");
    p.info = FindPrimitiveType(p.type);
    if (!p.info)
        ErrorExit(&p.loc,
                  "unknown type '" + p.type + "' (after modifier '" + p.modifier_name + "')");
    if (!Word(in, &p.name)) ErrorExit(&p.loc, "missing identifier for " + p.type);
    const bool surface =
        p.info->kind == PrimitiveKind::kSurface || p.info->kind == PrimitiveKind::kVolume;
    if (surface) p.name = cx.name_prefix + p.name;  // xform -n leaves modifiers' names alone
    if (surface && !cx.modifier_override.empty()) p.modifier_name = cx.modifier_override;
    if (p.info->kind == PrimitiveKind::kAlias) {
        std::string ref;
        if (!Word(in, &ref))
            ErrorExit(&p.loc, "alias '" + p.name + "' needs the name it refers to");
        auto it = modifiers_.find(ref);
        if (it == modifiers_.end() && !allow_undefined_)
            ErrorExit(&p.loc, "alias '" + p.name + "' refers to undefined '" + ref + "'");
        p.sargs.push_back(ref);
    } else {
        auto count = [&](const char *what) {
            FileLoc loc = in.Loc();
            int n;
            if (!Word(in, &w) || !ParseInt(w, &n) || n < 0)
                ErrorExit(&loc, p.type + " '" + p.name + "': bad " + what + " argument count '" +
                                    w + "'");
            return n;
        };
        int ns = count("string");
        for (int i = 0; i < ns; ++i) {
            if (!Word(in, &w))
                ErrorExit(&p.loc, p.type + " '" + p.name + "': missing string arguments");
            p.sargs.push_back(w);
        }
        if (count("integer") != 0)
            ErrorExit(&p.loc, p.type + " '" + p.name + "': integer arguments must be 0");
        int nf = count("real");
        for (int i = 0; i < nf; ++i) {
            FileLoc loc = in.Loc();
            double v;
            if (!Word(in, &w))
                ErrorExit(&loc, p.type + " '" + p.name + "': missing real arguments");
            if (!IsFloatWord(w) || !ParseNumber(w, &v))
                ErrorExit(&loc, p.type + " '" + p.name + "': real argument " +
                                    std::to_string(i + 1) + " '" + w + "' is not a number");
            p.fargs.push_back(v);
        }
    }
    if (p.modifier_name == "void") {
        p.modifier = -1;
    } else if (p.modifier_name == "inherit" && p.info->kind == PrimitiveKind::kAlias) {
        // "inherit alias new old": the copy keeps old's own modifier.
        auto it = modifiers_.find(p.sargs[0]);
        if (it != modifiers_.end()) {
            p.modifier = scene_->objects[it->second].modifier;
            p.modifier_name = scene_->objects[it->second].modifier_name;
        }
    } else {
        auto it = modifiers_.find(p.modifier_name);
        if (it != modifiers_.end())
            p.modifier = it->second;
        else if (!allow_undefined_)
            ErrorExit(&p.loc, "undefined modifier '" + p.modifier_name + "' for " + p.type + " '" +
                                  p.name + "'");
    }
    if (p.type == "mist" && !cx.name_prefix.empty()) {
        // xform -n prefixes the sources a mist names (each of "a>b"), as it did their names.
        for (std::string &s : p.sargs) {
            std::string named;
            for (size_t at = 0; at < s.size();) {
                const size_t gt = s.find('>', at);
                const size_t end = gt == std::string::npos ? s.size() : gt + 1;
                named += cx.name_prefix + s.substr(at, end - at);
                at = end;
            }
            s = named;
        }
    }
    p.xf = cx.xf;
    p.xforms = cx.xforms;
    CheckArguments(p);
    const int index = static_cast<int>(scene_->objects.size());
    if (!surface) modifiers_[p.name] = index;
    scene_->objects.push_back(std::move(p));
}

void CheckArguments(const Primitive &p) {
    const size_t ns = p.sargs.size(), nf = p.fargs.size();
    auto need = [&](bool ok, const std::string &what) {
        if (!ok)
            ErrorExit(&p.loc, p.type + " '" + p.name + "' needs " + what + " (has " +
                                  std::to_string(ns) + " strings, " + std::to_string(nf) +
                                  " reals)");
    };
    const std::string &t = p.type;
    if (t == "polygon")
        need(nf >= 9 && nf % 3 == 0, "3n reals with n >= 3");
    else if (t == "sphere" || t == "bubble")
        need(nf == 4, "4 reals (centre, radius)");
    else if (t == "cone" || t == "cup")
        need(nf == 8, "8 reals (two centres, two radii)");
    else if (t == "cylinder" || t == "tube")
        need(nf == 7, "7 reals (two centres, radius)");
    else if (t == "ring")
        need(nf == 8, "8 reals (centre, normal, two radii)");
    else if (t == "source")
        need(nf == 4, "4 reals (direction, angle)");
    else if (t == "plastic" || t == "metal")
        need(nf == 5, "5 reals");
    else if (t == "trans")
        need(nf == 7, "7 reals");
    else if (t == "glass")
        need(nf == 3 || nf == 4, "3 or 4 reals");
    else if (t == "dielectric")
        need(nf == 5, "5 reals");
    else if (t == "interface")
        need(nf == 8, "8 reals");
    else if (t == "light")
        need(nf == 3, "3 reals");
    else if (t == "glow")
        need(nf == 4, "4 reals");
    else if (t == "illum")
        need(nf == 3, "3 reals");
    else if (t == "spotlight")
        need(nf == 7, "7 reals");
    else if (t == "mirror")
        need(nf == 3 && ns <= 1, "3 reals and at most one string");
    else if (t == "plastic2" || t == "metal2")
        need(ns >= 4 && nf == 6, "4+ strings and 6 reals");
    else if (t == "trans2")
        need(ns >= 4 && nf == 8, "4+ strings and 8 reals");
    else if (t == "BSDF")
        need(ns >= 6 && (nf == 0 || nf == 3 || nf == 6 || nf == 9),
             "6+ strings and 0, 3, 6 or 9 reals");
    else if (t == "aBSDF")
        need(ns >= 5 && (nf == 0 || nf == 3 || nf == 6 || nf == 9),
             "5+ strings and 0, 3, 6 or 9 reals");
    else if (t == "brightfunc")
        need(ns >= 2, "2+ strings (function, file)");
    else if (t == "colorfunc")
        need(ns >= 4, "4+ strings (3 functions, file)");
    else if (t == "mixfunc")
        need(ns >= 4, "4+ strings (2 modifiers, function, file)");
    else if (t == "instance" || t == "mesh")
        need(ns >= 1, "a file name");
}

bool ParseXformCommand(const std::string &command, const FileLoc &loc, XformCommand *out) {
    const std::vector<std::string> args = SplitWords(command);
    if (args.empty() || args[0] != "xform" ||
        command.find_first_of("|;&<>$`'\"*?") != std::string::npos)
        return false;
    *out = XformCommand{};
    // As xform reads them: its own options, then the transform, then the files. Anything else
    // (-I, arrays, -i with a count, an option out of its place) goes to the real xform, which
    // does it or says what is wrong.
    size_t i = 1;
    for (; i < args.size(); ++i) {
        const std::string &a = args[i];
        if (a == "-m" && i + 1 < args.size()) {
            ++i;
            if (out->modifier.empty()) out->modifier = args[i];  // the first -m counts
        } else if (a == "-n" && i + 1 < args.size()) {
            out->name_prefix += args[++i] + ".";  // -n a -n b: "a.b."
        } else if (a != "-e" && a != "-c") {      // expand or keep commands: the same scene
            break;
        }
    }
    for (; i < args.size(); ++i) {
        if (args[i] == "-i" && (i + 1 >= args.size() || args[i + 1] != "1")) return false;
        if (!ApplyTransformOption(args, &i, loc, "xform", &out->xf)) break;
    }
    for (; i < args.size(); ++i) {
        if (args[i].size() > 1 && args[i][0] == '-') return false;
        out->files.push_back(args[i]);
    }
    if (out->files.empty()) out->files.push_back("-");
    // xform opens the options it adds to functions and instances with "-i 1" (resetarr).
    auto &words = out->xf.words;
    if (!words.empty() && words[0] != "-i") words.insert(words.begin(), {"-i", "1"});
    return true;
}

void SceneReader::Xform(const XformCommand &xform, const Context &cx) {
    Context inner = cx;
    // An outer xform's -m replaces what an inner one set.
    if (!xform.modifier.empty() && cx.modifier_override.empty())
        inner.modifier_override = xform.modifier;
    inner.name_prefix = cx.name_prefix + xform.name_prefix;
    inner.xf = xform.xf.Then(cx.xf);
    inner.xf.words.clear();  // each level keeps its own, in xforms
    auto levels = std::make_shared<std::vector<Transform>>(1, xform.xf);
    if (cx.xforms) levels->insert(levels->end(), cx.xforms->begin(), cx.xforms->end());
    inner.xforms = std::move(levels);
    inner.depth = cx.depth + 1;
    for (const std::string &f : xform.files) {
        if (f == "-") {
            auto in = InputSource::Open(f);
            Read(*in, inner);
            continue;
        }
        // xform reads a file from the folder it works in, else along RAYPATH, and works in the
        // file's folder while it does (openmain()): the files and commands the file names are
        // relative to it.
        const std::filesystem::path here =
            cx.dir.empty() ? std::filesystem::path(f) : std::filesystem::path(cx.dir) / f;
        const std::string path =
            std::filesystem::path(f).is_absolute() || std::filesystem::exists(here)
                ? here.string()
                : FindOnRaypath(f);
        inner.dir = std::filesystem::path(path).parent_path().string();
        auto in = InputSource::Open(path);
        Read(*in, inner);
    }
}

namespace {

// A command run from folder dir ("" for the working folder), as /bin/sh takes it.
std::string InFolder(const std::string &dir, const std::string &command) {
    if (dir.empty()) return command;
    std::string quoted = "'";
    for (char c : dir) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return "cd " + quoted + "' && " + command;
}

}  // namespace

void SceneReader::RunCommand(const std::string &command, const FileLoc &loc, const Context &cx) {
    if (cx.depth >= kMaxCommandDepth)
        ErrorExit(&loc, "commands nested too deep (a command that includes itself?)");
    if (SplitWords(command).empty()) ErrorExit(&loc, "empty command");
    XformCommand xform;  // its own errors name loc
    if (ParseXformCommand(command, loc, &xform)) {
        try {
            return Xform(xform, cx);
        } catch (const UserError &e) {
            ErrorExit(&loc, std::string("in '!") + command + "': " + e.what());
        }
    }
    auto in = InputSource::OpenNamedIn("!" + InFolder(cx.dir, command), loc);
    Context inner = cx;
    inner.depth = cx.depth + 1;
    try {
        Read(*in, inner);
    } catch (const UserError &e) {
        ErrorExit(&loc, std::string("in '!") + command + "': " + e.what());
    }
    if (!in->Close()) ErrorExit(&loc, "command '!" + command + "' failed");
}

Scene LoadScene(const std::vector<std::string> &inputs) {
    Scene scene;
    SceneReader reader(&scene);
    for (const std::string &in : inputs) {
        if (in != "-" && in[0] != '!' && IsOctreeFile(in))
            ReadOctree(in, &scene);
        else
            reader.ReadFile(in);
    }
    return scene;
}

Scene ReadScene(const std::vector<std::string> &paths) {
    Scene scene;
    SceneReader reader(&scene);
    for (const std::string &p : paths) reader.ReadFile(p);
    return scene;
}

}  // namespace dayflux
