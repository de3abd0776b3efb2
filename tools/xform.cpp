// xform: RADIANCE's scene transformer. Objects are read as words and written transformed, each
// type as xform writes it (surfaces' points moved, sizes scaled, functions and instances given the
// transform's options); -m -n -c -e -I, arrays (-a) and the transform options with -i; commands
// in the input run from the input file's folder and their output is transformed. Output byte for
// byte as RADIANCE 5.4a's xform, argument files (-f) included.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "matrix/header.h"
#include "scene/primitives.h"
#include "scene/xform_text.h"
#include "util/errors.h"
#include "util/raypath.h"
#include "util/strings.h"

namespace dayflux {
namespace {

using Mat4 = double[4][4];

void Identity(Mat4 m) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) m[i][j] = i == j;
}

void Multiply(Mat4 a, const Mat4 b, const Mat4 c) {  // a = b x c (multmat4())
    double t[4][4];
    for (int i = 4; i--;)
        for (int j = 4; j--;)
            t[i][j] = b[i][0] * c[0][j] + b[i][1] * c[1][j] + b[i][2] * c[2][j] + b[i][3] * c[3][j];
    std::memcpy(a, t, sizeof t);
}

struct Xf {
    Mat4 m;
    double sca = 1;
};

// RADIANCE's isint(): blanks, a sign, digits, blanks.
bool IsInt(const std::string &w) {
    size_t i = 0;
    while (i < w.size() && std::isspace(static_cast<unsigned char>(w[i]))) ++i;
    if (i < w.size() && (w[i] == '-' || w[i] == '+')) ++i;
    if (i >= w.size() || !std::isdigit(static_cast<unsigned char>(w[i]))) return false;
    while (i < w.size() && std::isdigit(static_cast<unsigned char>(w[i]))) ++i;
    while (i < w.size() && std::isspace(static_cast<unsigned char>(w[i]))) ++i;
    return i == w.size();
}

bool IsNumber(const std::string &w, bool integer) { return integer ? IsInt(w) : IsFloatWord(w); }

// xf(): the transform options from av[first]; returns how many words they took (it stops at the
// first word that is not one, or whose numbers are missing or bad).
int ParseXf(const std::vector<std::string> &av, size_t first, Xf *ret) {
    Identity(ret->m);
    ret->sca = 1.0;
    Mat4 xfmat, m4;
    Identity(xfmat);
    double xfsca = 1.0;
    int icnt = 1;
    size_t i = first;
    const auto args = [&](int n, bool integer) {  // badarg(): n numbers follow
        if (i + n >= av.size()) return false;
        for (int k = 1; k <= n; ++k)
            if (!IsNumber(av[i + k], integer)) return false;
        return true;
    };
    for (; i < av.size() && av[i][0] == '-'; ++i) {
        Identity(m4);
        const std::string &a = av[i];
        bool done = false;
        switch (a.size() > 1 ? a[1] : 0) {
            case 't':
                if (a.size() != 2 || !args(3, false)) {
                    done = true;
                    break;
                }
                for (int k = 0; k < 3; ++k) m4[3][k] = std::atof(av[++i].c_str());
                break;
            case 'r': {
                const char axis = a.size() > 2 ? a[2] : 0;
                if ((axis != 'x' && axis != 'y' && axis != 'z') || a.size() != 3 ||
                    !args(1, false)) {
                    done = true;
                    break;
                }
                const double d = (M_PI / 180.) * std::atof(av[++i].c_str());
                const int u = axis == 'x' ? 1 : axis == 'y' ? 0 : 0;
                const int w = axis == 'x' ? 2 : axis == 'y' ? 2 : 1;
                if (axis == 'y') {
                    m4[0][0] = m4[2][2] = std::cos(d);
                    m4[0][2] = -(m4[2][0] = std::sin(d));
                } else {
                    m4[u][u] = m4[w][w] = std::cos(d);
                    m4[w][u] = -(m4[u][w] = std::sin(d));
                }
                break;
            }
            case 's': {
                if (a.size() != 2 || !args(1, false)) {
                    done = true;
                    break;
                }
                const double v = std::atof(av[i + 1].c_str());
                if (v == 0.0) {
                    done = true;
                    break;
                }
                ++i;
                xfsca *= m4[0][0] = m4[1][1] = m4[2][2] = v;
                break;
            }
            case 'm': {
                const char axis = a.size() > 2 ? a[2] : 0;
                if ((axis != 'x' && axis != 'y' && axis != 'z') || a.size() != 3) {
                    done = true;
                    break;
                }
                const int k = axis - 'x';
                xfsca *= m4[k][k] = -1.0;
                break;
            }
            case 'i':
                if (a.size() != 2 || !args(1, true)) {
                    done = true;
                    break;
                }
                while (icnt-- > 0) {
                    Multiply(ret->m, ret->m, xfmat);
                    ret->sca *= xfsca;
                }
                icnt = std::atoi(av[++i].c_str());
                Identity(xfmat);
                xfsca = 1.0;
                continue;
            default:
                done = true;
        }
        if (done) break;
        Multiply(xfmat, xfmat, m4);
    }
    while (icnt-- > 0) {
        Multiply(ret->m, ret->m, xfmat);
        ret->sca *= xfsca;
    }
    return static_cast<int>(i - first);
}

void Point(double out[3], const double p[3], const Mat4 m) {  // multp3()
    double t[3];
    for (int j = 0; j < 3; ++j) t[j] = p[0] * m[0][j] + p[1] * m[1][j] + p[2] * m[2][j] + m[3][j];
    std::copy(t, t + 3, out);
}

void Vector(double out[3], const double v[3], const Mat4 m) {  // multv3()
    double t[3];
    for (int j = 0; j < 3; ++j) t[j] = v[0] * m[0][j] + v[1] * m[1][j] + v[2] * m[2][j];
    std::copy(t, t + 3, out);
}

// fgetword(): a word, or a quoted one; false at the end of input.
bool GetWord(std::FILE *f, std::string *w) {
    w->clear();
    int c;
    do c = std::getc(f);
    while (std::isspace(c));
    int quote = 0;
    if (c == '"' || c == '\'') {
        quote = c;
        c = std::getc(f);
    }
    while (c != EOF && !(quote ? c == quote : std::isspace(c))) {
        w->push_back(static_cast<char>(c));
        c = std::getc(f);
    }
    if (c == EOF) return !w->empty();
    if (!quote) std::ungetc(c, f);
    return true;
}

struct Args {  // FUNARGS
    std::vector<std::string> s;
    std::vector<double> f;
};

// readfargs()
bool ReadArgs(std::FILE *in, Args *a) {
    std::string w;
    const auto count = [&](int *n) {
        if (!GetWord(in, &w) || !IsInt(w) || (*n = std::atoi(w.c_str())) < 0) return false;
        return true;
    };
    int n;
    if (!count(&n)) return false;
    for (int i = 0; i < n; ++i) {
        if (!GetWord(in, &w)) return false;
        a->s.push_back(w);
    }
    if (!count(&n) || n != 0) return false;
    if (!count(&n)) return false;
    for (int i = 0; i < n; ++i) {
        if (!GetWord(in, &w) || !IsFloatWord(w)) return false;
        a->f.push_back(std::atof(w.c_str()));
    }
    return true;
}

class Xform {
  public:
    // main(): one run over the arguments (an array's element, too); returns its status.
    int Main(const std::vector<std::string> &av);

  private:
    int Run(const std::vector<std::string> &av);
    int Array(const std::vector<std::string> &av, size_t ai);
    int ArgumentFile(const std::vector<std::string> &av, size_t fi);

    void Transform(const std::string &name, std::FILE *in);
    void Command(const std::string &name, std::FILE *in);
    void Object(const std::string &name, std::FILE *in);
    bool Arguments(const std::string &type, std::FILE *in);
    void Print(const char *fmt, double v) { std::printf(fmt, v); }
    void OpenMain(const std::string *name);

    std::vector<std::string> xav_;
    size_t xfa_ = 0, xac_ = 0;
    Xf tot_;
    bool reverse_ = false, invert_ = false, expand_ = true;
    std::string newmod_, idprefix_;
    bool has_newmod_ = false, has_prefix_ = false;
    int nrept_ = 1;
    // openmain()'s state
    std::string main_name_, current_, original_dir_;
    std::FILE *main_ = nullptr;
    bool in_other_dir_ = false;
};

int Xform::Array(const std::vector<std::string> &av, size_t ai) {
    int n;
    if (ai + 1 >= av.size() || (n = std::atoi(av[ai + 1].c_str())) <= 0) {
        std::fprintf(stderr, "%s: missing count for -a option\n", av[0].c_str());
        std::exit(1);
    }
    nrept_ *= n;
    std::vector<std::string> args = av;
    std::string oldid;
    size_t id_at = 0;
    for (size_t i = 1; i < av.size(); ++i)
        if (av[i - 1] == "-n") oldid = av[i], id_at = i;
    int err = 0;
    for (int i = 0; i < n; ++i) {
        std::vector<std::string> a = args;
        const std::string newid =
            oldid.empty() ? "a" + std::to_string(i) : oldid + "." + std::to_string(i);
        a[ai] = "-i";
        a[ai + 1] = std::to_string(i);
        if (oldid.empty())
            a.insert(a.begin() + 1, {"-n", newid});
        else
            a[id_at] = newid;
        err |= Run(a);
    }
    return err;
}

int Xform::Run(const std::vector<std::string> &av) {
    invert_ = false;
    expand_ = true;
    has_newmod_ = has_prefix_ = false;
    newmod_.clear();
    idprefix_.clear();
    size_t a = 1;
    for (; a < av.size(); ++a) {
        const std::string &w = av[a];
        if (w[0] != '-') break;
        const bool alone = w.size() == 2;
        if (w.size() >= 2 && w[1] == 'm' && alone && a + 1 < av.size()) {
            ++a;
            if (!has_newmod_) newmod_ = av[a], has_newmod_ = true;
            continue;
        }
        if (w.size() >= 2 && w[1] == 'n' && alone && a + 1 < av.size()) {
            ++a;
            idprefix_ = has_prefix_ ? idprefix_ + "." + av[a] : av[a];
            has_prefix_ = true;
            continue;
        }
        if (w == "-c") {
            expand_ = false;
            continue;
        }
        if (w == "-e") {
            expand_ = true;
            continue;
        }
        if (w == "-I") {
            invert_ = !invert_;
            continue;
        }
        break;
    }
    xav_ = av;
    xfa_ = a;
    a += ParseXf(av, a, &tot_);
    reverse_ = tot_.sca < 0.0;
    if (reverse_) tot_.sca = -tot_.sca;
    if (invert_) reverse_ = !reverse_;
    if (a < av.size() && av[a][0] == '-') {
        std::fprintf(stderr, "%s: command line error at '%s'\n", av[0].c_str(), av[a].c_str());
        std::exit(1);
    }
    xac_ = a;
    std::putchar('#');
    for (size_t k = 0; k < xac_; ++k) std::printf(" %s", xav_[k].c_str());
    std::putchar('\n');
    if (xac_ == av.size()) {
        OpenMain(nullptr);
        Transform(main_name_, main_);
    } else {
        for (size_t k = xac_; k < av.size(); ++k) {
            OpenMain(&av[k]);
            Transform(main_name_, main_);
        }
    }
    return 0;
}

// openmain(): standard input (copied where an array reads it again), or a file found here or on
// RAYPATH, whose folder becomes the working one while commands are expanded.
void Xform::OpenMain(const std::string *name) {
    if (!name) {
        if (!main_) {
            main_name_ = "standard input";
            if (nrept_ <= 1) {
                main_ = stdin;
                return;
            }
            main_ = std::tmpfile();
            if (!main_) ErrorExit("cannot create temporary file");
            for (int c; (c = std::getc(stdin)) != EOF;) std::putc(c, main_);
        }
        std::rewind(main_);
        return;
    }
    if (!main_) {
        char buf[4096];
        if (getcwd(buf, sizeof buf)) original_dir_ = buf;
    } else if (*name == current_) {
        std::rewind(main_);
        return;
    } else {
        if (main_ != stdin) std::fclose(main_);
        main_ = nullptr;
        if (in_other_dir_) {
            if (chdir(original_dir_.c_str()) != 0) ErrorExit("cannot return to " + original_dir_);
            in_other_dir_ = false;
        }
    }
    current_ = *name;
    std::string path;
    try {
        path = FindOnRaypath(*name);
    } catch (const UserError &) {
        std::fprintf(stderr, "%s: cannot find file \"%s\"\n", xav_[0].c_str(), name->c_str());
        std::exit(1);
    }
    if (path.rfind("./", 0) == 0) path = path.substr(2);
    main_name_ = path;
    std::string open_path = path;
    if (expand_) {
        const size_t slash = path.rfind('/');
        if (slash != std::string::npos) {
            const std::string dir = slash == 0 ? "/" : path.substr(0, slash);
            if (chdir(dir.c_str()) != 0) {
                std::fprintf(stderr, "%s: cannot change directory to \"%s\"\n", xav_[0].c_str(),
                             dir.c_str());
                std::exit(1);
            }
            in_other_dir_ = true;
            open_path = name->substr(name->rfind('/') + 1);
        }
    }
    main_ = std::fopen(open_path.c_str(), "r");
    if (!main_) {
        std::fprintf(stderr, "%s: cannot open file \"%s\"\n", xav_[0].c_str(), main_name_.c_str());
        std::exit(1);
    }
}

void Xform::Transform(const std::string &name, std::FILE *in) {
    int objects = 0;
    for (int c; (c = std::getc(in)) != EOF;) {
        if (std::isspace(c)) continue;
        if (c == '#') {
            std::putchar(c);
            do {
                if ((c = std::getc(in)) == EOF) return;
                std::putchar(c);
            } while (c != '\n');
        } else if (c == '!') {
            std::ungetc(c, in);
            Command(name, in);
            ++objects;
        } else {
            std::ungetc(c, in);
            Object(name, in);
            ++objects;
        }
    }
    if (objects == 0)
        std::fprintf(stderr, "%s: (%s): warning - empty file\n", xav_[0].c_str(), name.c_str());
}

// xfcomm(): a command's output transformed (or, -c, the command kept with an xform after it).
void Xform::Command(const std::string &name, std::FILE *in) {
    std::string buf;  // fgetline(): a backslash before a newline continues the line
    for (int c; (c = std::getc(in)) != EOF;) {
        if (c == '\r' && (c = std::getc(in)) != '\n') {
            std::ungetc(c, in);
            c = '\n';
        }
        if (c == '\n' && (buf.empty() || buf.back() != '\\')) break;
        buf.push_back(static_cast<char>(c));
    }
    if (expand_) {
        std::fflush(stdout);
        std::FILE *pin = popen(buf.c_str() + 1, "r");
        if (!pin) {
            std::fprintf(stderr, "%s: (%s): cannot execute \"%s\"\n", xav_[0].c_str(), name.c_str(),
                         buf.c_str());
            std::exit(1);
        }
        Transform(buf, pin);
        pclose(pin);
    } else {
        std::printf("\n%s", buf.c_str());
        if (xac_ > 1) {
            std::printf(" | %s -e", xav_[0].c_str());
            for (size_t i = 1; i < xac_; ++i)
                if (i >= xfa_ || xav_[i] != "-c") std::printf(" %s", xav_[i].c_str());
        }
        std::putchar('\n');
    }
}

const char *Inverse(const std::string &t) {  // tinvers[]
    if (t == "cone") return "cup";
    if (t == "cup") return "cone";
    if (t == "sphere") return "bubble";
    if (t == "bubble") return "sphere";
    if (t == "cylinder") return "tube";
    if (t == "tube") return "cylinder";
    return t.c_str();
}

// xfobject()
void Xform::Object(const std::string &fname, std::FILE *in) {
    std::string mod, type, id;
    GetWord(in, &mod);
    if (!GetWord(in, &type)) type = "EOF";
    type = type.substr(0, 15);  // (read into 16 bytes)
    const PrimitiveType *info = FindPrimitiveType(type);
    if (!info) {
        std::fprintf(stderr, "%s: (%s): unknown object type \"%s\"\n", xav_[0].c_str(),
                     fname.c_str(), type.c_str());
        std::exit(1);
    }
    const bool modifier =
        info->kind != PrimitiveKind::kSurface && info->kind != PrimitiveKind::kVolume;
    std::putchar('\n');
    if (modifier) {
        std::printf("%s %s ", QuotedWord(mod).c_str(), type.c_str());
    } else {
        std::printf("%s %s ", QuotedWord(has_newmod_ ? newmod_ : mod).c_str(),
                    invert_ ? Inverse(type) : type.c_str());
    }
    GetWord(in, &id);
    std::printf("%s\n", QuotedWord(!has_prefix_ || modifier ? id : idprefix_ + "." + id).c_str());
    if (!Arguments(type, in)) {
        std::fprintf(stderr, "%s: (%s): bad %s \"%s\"\n", xav_[0].c_str(), fname.c_str(),
                     type.c_str(), id.c_str());
        std::exit(1);
    }
}

// Each type's arguments, as xform's o_*() and m_*() functions write them.
bool Xform::Arguments(const std::string &t, std::FILE *in) {
    if (t == "alias") {
        std::string name;
        if (!GetWord(in, &name)) return false;
        std::printf("\t%s\n", name.c_str());
        return true;
    }
    Args a;
    if (!ReadArgs(in, &a)) return false;
    const std::vector<double> &f = a.f;
    const size_t ns = a.s.size(), nf = f.size();
    const double sca = tot_.sca;
    double p[3], q[3];
    const auto line3 = [](const char *lead, const double *v) {
        std::printf("%s%18.12g %18.12g %18.12g\n", lead, v[0], v[1], v[2]);
    };
    if (t == "source") {
        if (ns != 0 || nf != 4) return false;
        Vector(p, &f[0], tot_.m);
        std::printf("0\n0\n4 %18.12g %18.12g %18.12g %18.12g\n", p[0], p[1], p[2], f[3]);
    } else if (t == "sphere" || t == "bubble") {
        if (ns != 0 || nf != 4) return false;
        Point(p, &f[0], tot_.m);
        std::printf("0\n0\n4 %18.12g %18.12g %18.12g %18.12g\n", p[0], p[1], p[2], f[3] * sca);
    } else if (t == "polygon") {
        if (ns != 0 || nf % 3) return false;
        std::printf("0\n0\n%zu\n", nf);
        for (size_t i = 0; i < nf; i += 3) {
            Point(p, &f[reverse_ ? nf - i - 3 : i], tot_.m);
            line3(" ", p);
        }
    } else if (t == "cone" || t == "cup" || t == "cylinder" || t == "tube") {
        const bool cyl = t == "cylinder" || t == "tube";
        if (ns != 0 || nf != (cyl ? 7u : 8u)) return false;
        std::printf("0\n0\n%d\n", cyl ? 7 : 8);
        Point(p, &f[0], tot_.m);
        Point(q, &f[3], tot_.m);
        line3(" ", p);
        line3(" ", q);
        if (cyl)
            std::printf(" %18.12g\n", f[6] * sca);
        else
            std::printf(" %18.12g %18.12g\n", f[6] * sca, f[7] * sca);
    } else if (t == "ring") {
        if (ns != 0 || nf != 8) return false;
        std::printf("0\n0\n8\n");
        Point(p, &f[0], tot_.m);
        Vector(q, &f[3], tot_.m);
        if (invert_)
            for (double &x : q) x = -x;
        line3(" ", p);
        line3(" ", q);
        std::printf(" %18.12g %18.12g\n", f[6] * sca, f[7] * sca);
    } else if (t == "glow") {
        if (ns != 0 || nf != 4) return false;
        std::printf("0\n0\n4 %18.12g %18.12g %18.12g %18.12g\n", f[0], f[1], f[2], f[3] * sca);
    } else if (t == "spotlight") {
        if (ns != 0 || nf != 7) return false;
        std::printf("0\n0\n7 %18.12g %18.12g %18.12g %18.12g\n", f[0], f[1], f[2], f[3]);
        Vector(p, &f[4], tot_.m);
        line3("\t", p);
    } else if (t == "dielectric") {
        if (ns != 0 || nf != 5) return false;
        std::printf("0\n0\n5 %12.6g %12.6g %12.6g %12.6g %12.6g\n", std::pow(f[0], 1.0 / sca),
                    std::pow(f[1], 1.0 / sca), std::pow(f[2], 1.0 / sca), f[3], f[4]);
    } else if (t == "interface") {
        if (ns != 0 || nf != 8) return false;
        std::printf("0\n0\n8\n%12.6g %12.6g %12.6g %12.6g\n", std::pow(f[0], 1.0 / sca),
                    std::pow(f[1], 1.0 / sca), std::pow(f[2], 1.0 / sca), f[3]);
        std::printf("%12.6g %12.6g %12.6g %12.6g\n", std::pow(f[4], 1.0 / sca),
                    std::pow(f[5], 1.0 / sca), std::pow(f[6], 1.0 / sca), f[7]);
    } else if (t == "mist") {
        if (nf > 7) return false;
        std::printf("%zu", ns);
        for (const std::string &s : a.s) {
            if (!has_prefix_) {
                std::printf(" %s", s.c_str());
                continue;
            }
            std::string named;  // each '>'-separated name gets the prefix
            for (size_t at = 0; at < s.size();) {
                named += idprefix_ + ".";
                const size_t gt = s.find('>', at);
                const size_t end = gt == std::string::npos ? s.size() : gt + 1;
                named += s.substr(at, end - at);
                at = end;
            }
            std::printf(" %s", named.c_str());
        }
        std::printf("\n0\n%zu", nf);
        if (nf > 2) std::printf(" %12.6g %12.6g %12.6g", f[0] / sca, f[1] / sca, f[2] / sca);
        for (size_t i = 3; i < nf; ++i) std::printf(" %12.6g", f[i]);
        std::printf("\n");
    } else if (t == "brighttext" || t == "colortext" || t == "mixtext") {
        if (nf < 9) return false;
        std::printf("%zu", ns);
        for (const std::string &s : a.s) std::printf(" %s", QuotedWord(s).c_str());
        std::printf("\n0\n%zu\n", nf);
        Point(p, &f[0], tot_.m);
        line3(" ", p);
        Vector(p, &f[3], tot_.m);
        line3(" ", p);
        Vector(p, &f[6], tot_.m);
        std::printf(" %18.12g %18.12g %18.12g", p[0], p[1], p[2]);
        for (size_t i = 9; i < nf; ++i) {
            if (i % 3 == 0) std::putchar('\n');
            std::printf(" %18.12g", f[i]);
        }
        std::putchar('\n');
    } else {
        // o_default(), or addxform() for functions, data, pictures, instances and meshes
        const bool add = XformAddsTransform(t);
        const int reset = add && xac_ > xfa_ && xav_[xfa_] != "-i" ? 2 : 0;
        std::printf("%zu", ns + (add ? reset + xac_ - xfa_ : 0));
        for (const std::string &s : a.s) std::printf(" %s", QuotedWord(s).c_str());
        if (add) {
            if (reset) std::printf(" -i 1");
            for (size_t i = xfa_; i < xac_; ++i) std::printf(" %s", xav_[i].c_str());
        }
        std::printf("\n0\n%zu", nf);
        for (double x : f) std::printf(" %18.12g", x);
        std::printf("\n");
    }
    return true;
}

// main(): an argument file, an array, or one transform.
int Xform::Main(const std::vector<std::string> &av) {
    for (size_t a = 1; a < av.size(); ++a)
        if (av[a] == "-f") return ArgumentFile(av, a);
    for (size_t a = 1; a < av.size(); ++a)
        if (av[a] == "-a") return Array(av, a);
    return Run(av);
}

// fgetline(): a line without its newline (a backslash before one continues it); false at the end.
bool GetLine(std::FILE *f, std::string *line) {
    line->clear();
    int c = EOF;
    while ((c = std::getc(f)) != EOF) {
        if (c == '\r' && (c = std::getc(f)) != '\n') {
            std::ungetc(c, f);
            c = '\n';
        }
        if (c == '\n' && (line->empty() || line->back() != '\\')) break;
        line->push_back(static_cast<char>(c));
    }
    return !(line->empty() && c == EOF);
}

// doargf(): one transform per line of the file (or of the standard input, "-"), each line's
// words in place of "-f file", each named i0, i1, ... (or after -n's name).
int Xform::ArgumentFile(const std::vector<std::string> &av, size_t fi) {
    if (fi + 1 >= av.size() || (av[fi + 1][0] == '-' && av[fi + 1].size() > 1)) {
        std::fprintf(stderr, "%s: missing file for -f option\n", av[0].c_str());
        std::exit(1);
    }
    std::FILE *f;
    int n = 0;
    std::string line;
    if (av[fi + 1] == "-") {
        f = stdin;
        n = 100;  // (as RADIANCE: the count is not known)
    } else {
        f = std::fopen(av[fi + 1].c_str(), "r");
        if (!f) {
            std::fprintf(stderr, "%s: cannot open argument file \"%s\"\n", av[0].c_str(),
                         av[fi + 1].c_str());
            std::exit(1);
        }
        while (GetLine(f, &line)) n += !line.empty() && line[0] != '#';
        if (!n) {
            std::fprintf(stderr, "%s: empty argument file \"%s\"\n", av[0].c_str(),
                         av[fi + 1].c_str());
            std::exit(1);
        }
        std::rewind(f);
    }
    nrept_ *= n;
    int err = 0, k = 0;
    while (GetLine(f, &line)) {
        if (line.empty() || line[0] == '#') {
            std::printf("%s\n", line.c_str());
            continue;
        }
        std::vector<std::string> args(av.begin(), av.begin() + static_cast<long>(fi));
        size_t at = line[0] == '!' ? 1 : 0;
        if (line.compare(at, 6, "xform ") == 0) at += 6;
        while (true) {  // the line's words: blanks between, quotes kept together
            while (at < line.size() && std::isspace(static_cast<unsigned char>(line[at]))) ++at;
            char quote = 0;
            if (at < line.size() && (line[at] == '"' || line[at] == '\'')) quote = line[at++];
            if (at >= line.size()) break;
            if (line[at] == '\\' && at + 1 < line.size() && line[++at] == '\n') continue;
            size_t end = at + 1;
            if (quote) {
                while (end < line.size() && line[end] != quote) ++end;
                args.push_back(line.substr(at, end - at));
                at = end + 1;
            } else {
                while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end])))
                    ++end;
                args.push_back(line.substr(at, end - at));
                at = end;
            }
        }
        args.insert(args.end(), av.begin() + static_cast<long>(fi) + 2, av.end());
        bool named = false;
        for (size_t i = 2; i < args.size(); ++i)
            if (args[i - 1] == "-n") {
                args[i] += "." + std::to_string(k);
                named = true;
                break;
            }
        if (!named) args.insert(args.begin() + 1, {"-n", "i" + std::to_string(k)});
        err |= Main(args);
        ++k;
    }
    if (f != stdin) std::fclose(f);
    return err;
}

int Main(int argc, char **argv) {
    Xform x;
    return x.Main(std::vector<std::string>(argv, argv + argc));
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
