#include "cal/klems_bins.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>

namespace dayflux::cal {

namespace {

// A number written as an argument: 0.5, or -0.5 (a negation of one).
bool Literal(const Node *n, double *v) {
    if (n->kind == Node::kNum) {
        *v = n->num;
        return true;
    }
    if (n->kind == Node::kNeg && n->kids.size() == 1 && n->kids[0]->kind == Node::kNum) {
        *v = -n->kids[0]->num;
        return true;
    }
    return false;
}

// The value of text in cx, or NaN where it cannot be evaluated.
double Value(const Context &cx, const std::string &text) {
    try {
        return cx.CompileInterpreted(text, FileLoc{"klems", 0}).Evaluate(cx);
    } catch (const UserError &) {
        return std::nan("");
    }
}

}  // namespace

std::unique_ptr<KlemsBins> KlemsBins::Recognise(const Context &cx, const Expression &e) {
    const Node *root = e.Root();
    if (!root || root->kind != Node::kCall || root->kids.size() != 7 ||
        root->kids[0]->kind != Node::kVar)
        return nullptr;
    const std::string &name = cx.SymbolName(root->kids[0]->index);
    if (name != "kbin" && name != "khbin" && name != "kqbin") return nullptr;
    auto k = std::make_unique<KlemsBins>();
    for (int i = 0; i < 3; ++i)
        if (!Literal(root->kids[1 + i].get(), &k->n_[i]) ||
            !Literal(root->kids[4 + i].get(), &k->u_[i]))
            return nullptr;
    const double *n = k->n_, *u = k->u_;
    k->nu_ = n[0] * u[0] + n[1] * u[1] + n[2] * u[2];
    k->cross_[0] = u[1] * n[2] - u[2] * n[1];
    k->cross_[1] = u[2] * n[0] - u[0] * n[2];
    k->cross_[2] = u[0] * n[1] - u[1] * n[0];
    k->minus_rhs_ = -Value(cx, "RHS");
    // DEGREE is a constant (':'), so `x/DEGREE` is parsed as x times its reciprocal (calcomp.cpp)
    k->per_degree_ = 1. / Value(cx, "DEGREE");
    const double rings = Value(cx, "kpola(0)");
    if (!(rings >= 1 && rings <= 64) || Value(cx, "knaz(0)") != rings ||
        !std::isfinite(k->minus_rhs_) || !(k->per_degree_ > 0))
        return nullptr;
    double before = 0;
    for (int r = 1; r <= static_cast<int>(rings); ++r) {
        const std::string ring = std::to_string(r);
        const double upper = Value(cx, "kpola(" + ring + ")"),
                     patches = Value(cx, "knaz(" + ring + ")");
        if (!(patches >= 1) || !std::isfinite(upper)) return nullptr;
        k->upper_.push_back(upper);
        k->azimuths_.push_back(patches);
        k->first_.push_back(before);
        before += patches;
    }
    // The same bins as the expression, on directions all about the sphere (a fixed sequence),
    // the axes and the frame's own.
    std::vector<std::array<double, 3>> dirs = {{1, 0, 0},
                                               {-1, 0, 0},
                                               {0, 1, 0},
                                               {0, -1, 0},
                                               {0, 0, 1},
                                               {0, 0, -1},
                                               {-n[0], -n[1], -n[2]},
                                               {n[0], n[1], n[2]},
                                               {-u[0], -u[1], -u[2]}};
    uint64_t state = 0x9e3779b97f4a7c15ull;
    const auto next = [&state] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) * 0x1p-53;
    };
    for (int i = 0; i < 4096; ++i) {
        const double z = 1 - 2 * next(), phi = 2 * M_PI * next(), s = std::sqrt(1 - z * z);
        dirs.push_back({s * std::cos(phi), s * std::sin(phi), z});
    }
    // and along the rings' and patches' edges in this frame, where a step taken in another
    // order would round across an edge
    double x[3] = {u[0] - k->nu_ * n[0], u[1] - k->nu_ * n[1], u[2] - k->nu_ * n[2]};
    const double xl = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    if (xl > 1e-6) {
        for (double &c : x) c /= xl;
        const double y[3] = {n[1] * x[2] - n[2] * x[1], n[2] * x[0] - n[0] * x[2],
                             n[0] * x[1] - n[1] * x[0]};
        for (size_t r = 0; r < k->upper_.size(); ++r) {
            const double pol = k->upper_[r] * M_PI / 180, count = k->azimuths_[r];
            for (int j = 0; j < 2 * count; ++j) {
                const double azi = (j + .5) * M_PI / count;
                const double a = std::sin(pol) * std::cos(azi), b = std::sin(pol) * std::sin(azi);
                dirs.push_back({-(std::cos(pol) * n[0] + a * x[0] + b * y[0]),
                                -(std::cos(pol) * n[1] + a * x[1] + b * y[1]),
                                -(std::cos(pol) * n[2] + a * x[2] + b * y[2])});
            }
        }
    }
    ChannelArray channels(std::vector<double>(27, 0.0));
    for (const auto &d : dirs) {
        for (int i = 0; i < 3; ++i) channels.values()[i] = d[i];
        double expected;
        try {
            expected = e.Evaluate(cx, &channels);
        } catch (const UserError &) {
            return nullptr;
        }
        if (k->Bin(d[0], d[1], d[2]) != expected) return nullptr;
    }
    return k;
}

double KlemsBins::Bin(const Channels *channels) const {
    return Bin(channels->Value(1), channels->Value(2), channels->Value(3));
}

// kbin(N, U) of the .cal files, step by step in their order: the polar angle
// Acos(-D.N)/DEGREE, its ring (kring), the azimuth mod(Atan2(...)/DEGREE, 360) and its patch
// (kazn), the ring's first bin (kcum).
double KlemsBins::Bin(double dx, double dy, double dz) const {
    const double *n = n_, *u = u_;
    double c = -dx * n[0] - dy * n[1] - dz * n[2];
    c = -1 - c > 0 ? -1 : c - 1 > 0 ? 1 : c;  // bound(-1, c, 1)
    const double pol = std::acos(c) * per_degree_;
    if (pol - 90 > 0) return -1;
    size_t ring = 0;  // kring: the first ring whose upper angle pol does not pass
    while (ring + 1 < upper_.size() && pol - upper_[ring] > 0) ++ring;
    const double y = -dx * u[0] - dy * u[1] - dz * u[2] + (n[0] * dx + n[1] * dy + n[2] * dz) * nu_;
    const double x = minus_rhs_ * (dx * cross_[0] + dy * cross_[1] + dz * cross_[2]);
    const double angle = x * x + y * y > 0 ? std::atan2(y, x) : 0;  // Atan2
    const double t = angle * per_degree_;
    const double azi = t - std::floor(t / 360) * 360;  // mod(t, 360)
    const double inc = 360 / azimuths_[ring];
    const double patch = (360 - .5 * inc) - azi > 0 ? std::floor((azi + .5 * inc) / inc) : 0;
    return first_[ring] + patch;
}

}  // namespace dayflux::cal
