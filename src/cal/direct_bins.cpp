#include "cal/direct_bins.h"

#include <algorithm>
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
        return cx.CompileInterpreted(text, FileLoc{"bins", 0}).Evaluate(cx);
    } catch (const UserError &) {
        return std::nan("");
    }
}

// The name of a variable (rbin) or of a called function (kbin), else "".
std::string NameOf(const Context &cx, const Node *root) {
    if (!root) return "";
    if (root->kind == Node::kVar) return cx.SymbolName(root->index);
    if (root->kind == Node::kCall && root->kids[0]->kind == Node::kVar)
        return cx.SymbolName(root->kids[0]->index);
    return "";
}

// bound(-1, c, 1) of rayinit.cal.
double Bound(double c) { return -1 - c > 0 ? -1 : c - 1 > 0 ? 1 : c; }

// mod(Atan2(y, x) / DEGREE, 360) of rayinit.cal, in degrees.
double Azimuth(double y, double x, double per_degree) {
    const double t = (x * x + y * y > 0 ? std::atan2(y, x) : 0) * per_degree;
    return t - std::floor(t / 360) * 360;
}

// Whether bins gives e's bins: on 4096 directions all about the sphere (a fixed sequence), the
// axes and its edges.
bool SameBins(const Context &cx, const Expression &e, const DirectBins &bins,
              std::vector<std::array<double, 3>> dirs) {
    for (const std::array<double, 3> axis : std::vector<std::array<double, 3>>{
             {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}})
        dirs.push_back(axis);
    uint64_t state = 0x9e3779b97f4a7c15ull;
    const auto next = [&state] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) * 0x1p-53;
    };
    for (int i = 0; i < 4096; ++i) {
        const double z = 1 - 2 * next(), phi = 2 * M_PI * next(), s = std::sqrt(1 - z * z);
        dirs.push_back({s * std::cos(phi), s * std::sin(phi), z});
    }
    // The other ray variables hold numbers of their own: a bin that reads them is not these.
    std::vector<double> values(27);
    for (double &v : values) v = 2 * next() - 1;
    ChannelArray channels(values);
    for (const auto &d : dirs) {
        for (int i = 0; i < 3; ++i) channels.values()[i] = d[i];
        try {
            if (bins.Bin(d[0], d[1], d[2]) != e.Evaluate(cx, &channels)) return false;
        } catch (const UserError &) {
            return false;
        }
    }
    return true;
}

}  // namespace

std::unique_ptr<DirectBins> DirectBins::Recognise(const Context &cx, const Expression &e) {
    std::unique_ptr<DirectBins> bins = KlemsBins::Make(cx, e);
    if (!bins) bins = ReinhartBins::Make(cx, e);
    if (!bins || !SameBins(cx, e, *bins, bins->EdgeDirections())) return nullptr;
    return bins;
}

double DirectBins::Bin(const Channels *channels) const {
    return Bin(channels->Value(1), channels->Value(2), channels->Value(3));
}

// ---- Klems

std::unique_ptr<KlemsBins> KlemsBins::Make(const Context &cx, const Expression &e) {
    const Node *root = e.Root();
    const std::string name = NameOf(cx, root);
    if ((name != "kbin" && name != "khbin" && name != "kqbin") || root->kind != Node::kCall ||
        root->kids.size() != 7)
        return nullptr;
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
    // DEGREE is a constant (':'), so `x/DEGREE` is parsed as x times its reciprocal
    k->per_degree_ = 1. / Value(cx, "DEGREE");
    k->cosine_rings_ = std::abs(k->per_degree_ * M_PI / 180 - 1) < 1e-12;
    const double rings = Value(cx, "kpola(0)");
    if (!(rings >= 1 && rings <= 64) || Value(cx, "knaz(0)") != rings ||
        !std::isfinite(k->minus_rhs_) || !(k->per_degree_ > 0))
        return nullptr;
    double before = 0;
    for (int r = 1; r <= static_cast<int>(rings); ++r) {
        const std::string ring = std::to_string(r);
        const double upper = Value(cx, "kpola(" + ring + ")"),
                     patches = Value(cx, "knaz(" + ring + ")");
        if (!(patches >= 1 && patches <= 4096) || !std::isfinite(upper)) return nullptr;
        k->upper_.push_back(upper);
        // cosines fall as the angle grows only within [0, 180] degrees, and c < 0 is the
        // horizon's test only with DEGREE in radians
        if (!(upper >= 0 && upper <= 180)) k->cosine_rings_ = false;
        k->cos_upper_.push_back(std::cos(upper / k->per_degree_));
        k->azimuths_.push_back(patches);
        k->first_.push_back(before);
        before += patches;
    }
    return k;
}

// Along the rings' edges and the patches' edges in the call's own frame.
std::vector<std::array<double, 3>> KlemsBins::EdgeDirections() const {
    const double *n = n_, *u = u_;
    std::vector<std::array<double, 3>> dirs = {
        {-n[0], -n[1], -n[2]}, {n[0], n[1], n[2]}, {-u[0], -u[1], -u[2]}};
    double x[3] = {u[0] - nu_ * n[0], u[1] - nu_ * n[1], u[2] - nu_ * n[2]};
    const double xl = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    if (!(xl > 1e-6)) return dirs;
    for (double &c : x) c /= xl;
    const double y[3] = {n[1] * x[2] - n[2] * x[1], n[2] * x[0] - n[0] * x[2],
                         n[0] * x[1] - n[1] * x[0]};
    for (size_t r = 0; r < upper_.size(); ++r) {
        const double pol = upper_[r] * M_PI / 180, count = azimuths_[r];
        for (int j = 0; j < count; ++j) {  // patches are centred on multiples of 360 / count
            const double azi = (j + .5) * 2 * M_PI / count;
            const double a = std::sin(pol) * std::cos(azi), b = std::sin(pol) * std::sin(azi);
            dirs.push_back({-(std::cos(pol) * n[0] + a * x[0] + b * y[0]),
                            -(std::cos(pol) * n[1] + a * x[1] + b * y[1]),
                            -(std::cos(pol) * n[2] + a * x[2] + b * y[2])});
        }
    }
    return dirs;
}

// kbin(N, U) of the .cal files, step by step in their order: the polar angle
// Acos(-D.N)/DEGREE, its ring (kring), the azimuth mod(Atan2(...)/DEGREE, 360) and its patch
// (kazn), the ring's first bin (kcum).
double KlemsBins::Bin(double dx, double dy, double dz) const {
    const double *n = n_, *u = u_;
    const double c = Bound(-dx * n[0] - dy * n[1] - dz * n[2]);
    size_t ring = 0;  // kring: the first ring whose upper angle the polar angle does not pass
    if (!RingByCosine(c, &ring)) {  // near an edge: as the .cal file decides it
        const double pol = std::acos(c) * per_degree_;
        if (pol - 90 > 0) return -1;
        ring = 0;
        while (ring + 1 < upper_.size() && pol - upper_[ring] > 0) ++ring;
    } else if (c < 0) {
        return -1;
    }
    const double y = -dx * u[0] - dy * u[1] - dz * u[2] + (n[0] * dx + n[1] * dy + n[2] * dz) * nu_;
    const double x = minus_rhs_ * (dx * cross_[0] + dy * cross_[1] + dz * cross_[2]);
    const double azi = Azimuth(y, x, per_degree_);
    const double inc = 360 / azimuths_[ring];
    const double patch = (360 - .5 * inc) - azi > 0 ? std::floor((azi + .5 * inc) / inc) : 0;
    return first_[ring] + patch;
}

// The ring of polar cosine c by comparing cosines (acos was 4 % of a V matrix's run), where c
// lies clear of every edge it is compared with (the horizon's and the rings'): there the
// comparison decides as acos's would, whose rounding moves an angle by far less. False near an
// edge.
bool KlemsBins::RingByCosine(double c, size_t *ring) const {
    constexpr double kClear = 1e-9;
    if (!cosine_rings_ || !(std::abs(c) >= kClear)) return false;  // (NaN too)
    size_t r = 0;
    for (;; ++r) {
        if (std::abs(c - cos_upper_[r]) < kClear) return false;
        if (r + 1 >= cos_upper_.size() || c > cos_upper_[r]) break;
    }
    *ring = r;
    return true;
}

// ---- Reinhart

std::unique_ptr<ReinhartBins> ReinhartBins::Make(const Context &cx, const Expression &e) {
    if (NameOf(cx, e.Root()) != "rbin" || e.Root()->kind != Node::kVar) return nullptr;
    auto k = std::make_unique<ReinhartBins>();
    k->mf_ = Value(cx, "MF");
    k->alpha_ = Value(cx, "ralpha");
    // (MF above 16: its check would take seconds per compile; such skies keep the program)
    if (!(k->mf_ >= 1 && k->mf_ <= 16 && k->mf_ == std::floor(k->mf_)) || !(k->alpha_ > 0))
        return nullptr;
    // MF, ralpha and DEGREE are constants: division by them is multiplication by the reciprocal
    k->per_mf_ = 1. / k->mf_;
    k->per_alpha_ = 1. / k->alpha_;
    k->per_degree_ = 1. / Value(cx, "DEGREE");
    if (!(k->per_degree_ > 0)) return nullptr;
    return k;
}

double ReinhartBins::Patches(double row) const {
    static const double kBand[] = {30, 30, 24, 24, 18, 12, 6};
    if (row - (7 * mf_ - .5) > 0) return 1;
    return mf_ * kBand[static_cast<int>(std::floor(row * per_mf_))];
}

double ReinhartBins::Below(double row) const {
    static const double kBand[] = {30, 30, 24, 24, 18, 12, 6, 1};
    static const double kCum[] = {0, 30, 60, 84, 108, 126, 138, 144};
    if (row - (7 * mf_ + .5) > 0) return 144 * mf_ * mf_ + 1;
    const double b = std::floor(row * per_mf_);
    const int band = static_cast<int>(b);
    return mf_ * mf_ * kCum[band] + (row - mf_ * b) * mf_ * kBand[band];
}

// rbin of reinhart.cal, step by step in its order: the altitude Asin(Dz)/DEGREE and its row
// (rrow), the azimuth from north toward east and its patch (razn), the patches below the row.
double ReinhartBins::Bin(double dx, double dy, double dz) const {
    if (-dz > 0) return 0;
    const double alt = std::asin(Bound(dz)) * per_degree_;
    const double row = std::min(std::floor(alt * per_alpha_), 7 * mf_);
    if (std::isnan(row)) return -1;  // (calcomp's select() stops there: a bad bin here)
    const double azi = Azimuth(dx, dy, per_degree_);
    const double inc = 360 / Patches(row);
    const double patch = (359.9999 - .5 * inc) - azi > 0 ? std::floor((azi + .5 * inc) / inc) : 0;
    return Below(row) + patch + 1;
}

// On each row's lower edge and its patches' edges (azimuths from north toward east).
std::vector<std::array<double, 3>> ReinhartBins::EdgeDirections() const {
    std::vector<std::array<double, 3>> dirs;
    const int rows = static_cast<int>(7 * mf_);
    for (int r = 0; r <= rows; ++r) {
        const double count = Patches(r);
        for (double alt : {r * alpha_, (r + .5) * alpha_}) {
            const double a = std::min(alt, 90.) * M_PI / 180;
            for (int j = 0; j < count; ++j) {  // centred on multiples of 360 / count
                const double azi = (j + .5) * 2 * M_PI / count;
                dirs.push_back(
                    {std::cos(a) * std::sin(azi), std::cos(a) * std::cos(azi), std::sin(a)});
            }
        }
    }
    return dirs;
}

}  // namespace dayflux::cal
