#include "scene/xform_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace dayflux {

namespace {

// A number printed with printf's %.<digits>g and read back with atof, as xform and oconv do.
double Printed(double x, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    return std::atof(buf);
}

bool OneOf(const std::string &t, std::initializer_list<const char *> names) {
    return std::any_of(names.begin(), names.end(), [&](const char *n) { return t == n; });
}

}  // namespace

// Types whose string arguments take the transform (otypes.h's hasfunc: functions, data, pictures),
// and instances and meshes (addxform()).
bool XformAddsTransform(const std::string &t) {
    return OneOf(t, {"texfunc",    "plastic2",   "metal2",    "trans2",    "plasfunc",  "metfunc",
                     "brightfunc", "brightdata", "colorpict", "transfunc", "BRTDfunc",  "BSDF",
                     "aBSDF",      "plasdata",   "metdata",   "transdata", "colorfunc", "colordata",
                     "texdata",    "mixfunc",    "mixdata",   "mixpict",   "prism1",    "prism2",
                     "ashik2",     "instance",   "mesh"});
}

namespace {

// One xform command's rewriting.
class XformPrinter {
  public:
    explicit XformPrinter(const Transform &xf)
        : xf_(xf), scale_(std::fabs(xf.scale)), mirrored_(xf.Mirrors()) {}

    void Print(Primitive *p) const {
        std::vector<double> &f = p->fargs;
        const std::string &t = p->type;
        if (t == "polygon") {
            std::vector<double> v(f.size());
            const size_t n = f.size() / 3;
            for (size_t i = 0; i < n; ++i)  // a mirror reverses the vertices (xform's reverse)
                xf_.Apply(&f[3 * (mirrored_ ? n - 1 - i : i)], &v[3 * i]);
            f = v;
        } else if (t == "sphere" || t == "bubble") {
            Point(&f[0]);
            f[3] *= scale_;
        } else if (OneOf(t, {"cone", "cup", "cylinder", "tube"})) {
            Point(&f[0]);
            Point(&f[3]);
            for (size_t i = 6; i < f.size(); ++i) f[i] *= scale_;
        } else if (t == "ring") {
            Point(&f[0]);
            Direction(&f[3]);
            f[6] *= scale_;
            f[7] *= scale_;
        } else if (t == "source") {
            Direction(&f[0]);
        } else if (t == "glow") {
            f[3] *= scale_;
        } else if (t == "spotlight") {
            Direction(&f[4]);
        } else if (OneOf(t, {"brighttext", "colortext", "mixtext"}) && f.size() >= 9) {
            Point(&f[0]);
            Direction(&f[3]);
            Direction(&f[6]);
        } else if (t == "dielectric" || t == "interface") {
            // Colours per unit length: xform turns them with the scale, in six digits.
            for (size_t i = 0; i < f.size(); ++i) {
                if (t == "dielectric" ? i < 3 : i % 4 != 3) f[i] = std::pow(f[i], 1.0 / scale_);
                f[i] = Printed(f[i], 6);
            }
            return;
        } else if (t == "mist") {
            for (size_t i = 0; i < f.size(); ++i) {
                if (i < 3 && f.size() > 2) f[i] /= scale_;
                f[i] = Printed(f[i], 6);
            }
            return;
        }
        for (double &x : f) x = Printed(x, 12);
        if (XformAddsTransform(t))
            p->sargs.insert(p->sargs.end(), xf_.words.begin(), xf_.words.end());
    }

  private:
    void Point(double *v) const {
        double out[3];
        xf_.Apply(v, out);
        std::copy(out, out + 3, v);
    }
    void Direction(double *v) const {
        double out[3];
        xf_.ApplyDirection(v, out);
        std::copy(out, out + 3, v);
    }

    const Transform &xf_;
    double scale_;
    bool mirrored_;
};

}  // namespace

Primitive AsXformPrints(const Primitive &p) {
    Primitive out = p;
    if (p.xforms)
        for (const Transform &level : *p.xforms) XformPrinter(level).Print(&out);
    return out;
}

}  // namespace dayflux
