#include "raytrace/klems.h"

#include <algorithm>
#include <cmath>

namespace dayflux {

namespace {

// fo_getndx()'s frame: front outgoing directions have z > 0; the other three mappings of
// bsdf_m.c mirror into it (and back: each is its own inverse).
void ToFrontOut(bool incident, bool front, const double v[3], double w[3]) {
    w[0] = incident ? -v[0] : v[0];
    w[1] = incident ? -v[1] : v[1];
    w[2] = front ? v[2] : -v[2];
}

// fo_getvec(): a direction in patch `index`, uniform in projected solid angle (u, v in [0,1)).
void PatchDirection(const AngleBasis &b, int index, double u, double v, double w[3]) {
    size_t ring = 0;
    while (index >= b.nphis[ring]) index -= b.nphis[ring++];
    const double c0 = std::cos(M_PI / 180. * b.theta[ring]);
    const double c1 = std::cos(M_PI / 180. * b.theta[ring + 1]);
    const double cz = std::sqrt((1. - u) * c0 * c0 + u * c1 * c1);
    const double azi = 2. * M_PI * (index + v - .5) / b.nphis[ring];
    const double sz = std::sqrt(std::max(0., 1. - cz * cz));
    w[0] = std::cos(azi) * sz;
    w[1] = std::sin(azi) * sz;
    w[2] = cz;
}

}  // namespace

void KlemsScattering::BasisTable::Set(const AngleBasis &b) {
    cos_bounds.clear(), ohm.clear(), first.clear();
    nphis = b.nphis;
    for (double t : b.theta) cos_bounds.push_back(std::cos(M_PI / 180. * t));
    for (int i = 0; i < b.Size(); ++i) ohm.push_back(b.ProjectedSolidAngle(i));
    int n = 0;
    for (int p : nphis) first.push_back(n), n += p;
}

// fo_getndx(): the ring whose polar bounds hold the direction (compared as cosines), then the
// azimuth patch centred on multiples of 360 / nphis.
int KlemsScattering::BasisTable::IndexOf(const double w[3]) const {
    const double z = w[2];
    if (z < 0 || z > 1.00001) return -1;
    const size_t rings = nphis.size();
    if (z < cos_bounds[rings]) return -1;
    size_t ring = 0;
    while (ring + 1 < rings && z <= cos_bounds[ring + 1]) ++ring;
    double azi = 180.0 / M_PI * std::atan2(w[1], w[0]);
    if (azi < 0) azi += 360.0;
    int ndx = static_cast<int>((1. / 360.) * azi * nphis[ring] + 0.5);
    if (ndx >= nphis[ring]) ndx = 0;
    return first[ring] + ndx;
}

int KlemsScattering::Part::InIndex(const double v[3]) const {
    double w[3];
    ToFrontOut(true, in_front, v, w);
    return in_table.IndexOf(w);
}

int KlemsScattering::Part::OutIndex(const double v[3]) const {
    double w[3];
    ToFrontOut(false, out_front, v, w);
    return out_table.IndexOf(w);
}

KlemsScattering::KlemsScattering(const KlemsBsdf &d)
    : r_lamb_front_(d.r_lamb_front),
      r_lamb_back_(d.r_lamb_back),
      t_lamb_front_(d.t_lamb_front),
      t_lamb_back_(d.t_lamb_back) {
    rf_.data = d.rf;
    rb_.data = d.rb;
    tf_.data = d.tf;
    tb_.data = d.tb;
    Prepare(&rf_, true, true);
    Prepare(&rb_, false, false);
    Prepare(&tf_, true, false);
    Prepare(&tb_, false, true);
}

// The cumulative distributions make_cdist() builds on demand, all at once: the matrices are
// small and the integrator's threads then share them read-only.
void KlemsScattering::Prepare(Part *p, bool in_front, bool out_front) {
    p->in_front = in_front;
    p->out_front = out_front;
    if (!p->present()) return;
    p->in_table.Set(p->data.in);
    p->out_table.Set(p->data.out);
    const int nin = p->data.in.Size(), nout = p->data.out.Size();
    p->cdf.assign(nin, std::vector<double>(nout + 1, 0.));
    for (int i = 0; i < nin; ++i)
        for (int o = 0; o < nout; ++o)
            p->cdf[i][o + 1] = p->cdf[i][o] + p->Value(o, i) * p->OutProjSA(o);
    p->reverse_cdf.assign(nout, std::vector<double>(nin + 1, 0.));
    for (int o = 0; o < nout; ++o)
        for (int i = 0; i < nin; ++i)
            p->reverse_cdf[o][i + 1] = p->reverse_cdf[o][i] + p->Value(o, i) * p->InProjSA(i);
}

const KlemsScattering::Part *KlemsScattering::Transmission(bool front) const {
    const Part &own = front ? tf_ : tb_, &other = front ? tb_ : tf_;
    if (own.present()) return &own;
    return other.present() ? &other : nullptr;
}

const KlemsScattering::Part *KlemsScattering::Reflection(bool front) const {
    const Part &p = front ? rf_ : rb_;
    return p.present() ? &p : nullptr;
}

double KlemsScattering::Eval(const double in[3], const double out[3]) const {
    const bool in_front = in[2] > 0, out_front = out[2] > 0;
    double value;
    const Part *p;
    if (in_front == out_front) {
        value = ReflectionLambertian(in_front);
        p = Reflection(in_front);
    } else {
        value = TransmissionLambertian(in_front);
        p = Transmission(in_front);
    }
    value *= 1. / M_PI;
    if (!p) return value;
    int i = p->InIndex(in), o = p->OutIndex(out);
    if (i < 0 && o < 0) i = p->InIndex(out), o = p->OutIndex(in);  // reciprocity
    if (i < 0 || o < 0) return value;
    return value + p->Value(o, i);
}

double KlemsScattering::SpecularHemi(const double in[3], bool transmission) const {
    const bool front = in[2] > 0;
    const Part *p = transmission ? Transmission(front) : Reflection(front);
    if (!p) return 0;
    if (const int i = p->InIndex(in); i >= 0) return p->cdf[i].back();
    if (const int o = p->OutIndex(in); o >= 0) return p->reverse_cdf[o].back();
    return 0;
}

// SDqueryMtxProjSA(): psa[0] the smallest, psa[1] (minmax) the largest patch met.
void KlemsScattering::QueryProjSA(const Part &p, const double v1[3], const double v2[3],
                                  bool minmax, double psa[2]) const {
    double out_psa = p.OutProjSA(p.OutIndex(v1));
    double inc_psa = p.InProjSA(p.InIndex(v2));
    if (v1 != v2 && out_psa <= 0 && inc_psa <= 0) {
        inc_psa = p.OutProjSA(p.OutIndex(v2));
        out_psa = p.InProjSA(p.InIndex(v1));
    }
    if (minmax) psa[1] = std::max({psa[1], inc_psa, out_psa});
    if (inc_psa > 0 && inc_psa < psa[0]) psa[0] = inc_psa;
    if (out_psa > 0 && out_psa < psa[0]) psa[0] = out_psa;
}

void KlemsScattering::SizeMinMax(const double v[3], double *min, double *max) const {
    const bool front = v[2] > 0;
    double psa[2] = {10., 0.};
    bool any = false;
    for (const Part *p : {Reflection(front), Transmission(front)})
        if (p) QueryProjSA(*p, v, v, true, psa), any = true;
    if (!any) psa[0] = psa[1] = M_PI;
    if (psa[0] > psa[1]) psa[0] = psa[1];
    *min = psa[0];
    *max = psa[1];
}

double KlemsScattering::SizeMin(const double v1[3], const double v2[3]) const {
    const bool front = v1[2] > 0;
    const Part *p = (v1[2] > 0) != (v2[2] > 0) ? Transmission(front) : Reflection(front);
    if (!p) return M_PI;
    double psa[2] = {10., 0.};
    QueryProjSA(*p, v1, v2, false, psa);
    return psa[0];
}

double KlemsScattering::Sample(const Part &p, const double in[3], double rand, double u, double v,
                               double out[3]) {
    const std::vector<double> *cdf = nullptr;
    const AngleBasis *basis;
    bool incident, front;
    if (const int i = p.InIndex(in); i >= 0) {
        cdf = &p.cdf[i];
        basis = &p.data.out;
        incident = false, front = p.out_front;
    } else if (const int o = p.OutIndex(in); o >= 0) {  // reciprocity
        cdf = &p.reverse_cdf[o];
        basis = &p.data.in;
        incident = true, front = p.in_front;
    } else {
        return 0;
    }
    const double total = cdf->back();
    if (total <= 1e-6) return 0;
    // The patch whose share of the total holds rand.
    const double target = std::clamp(rand, 0., 1.) * total;
    int k = static_cast<int>(std::upper_bound(cdf->begin() + 1, cdf->end(), target) -
                             (cdf->begin() + 1));
    k = std::min(k, static_cast<int>(cdf->size()) - 2);
    double w[3];
    PatchDirection(*basis, k, u, v, w);
    ToFrontOut(incident, front, w, out);
    return total;
}

}  // namespace dayflux

namespace dayflux {

namespace {
double Dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
bool Normalize(double v[3]) {
    const double l = std::sqrt(Dot(v, v));
    if (l == 0) return false;
    for (int k = 0; k < 3; ++k) v[k] /= l;
    return true;
}
}  // namespace

bool KlemsHit::Set(const KlemsScattering &k, const double front_normal[3], const double up[3],
                   const double ray_dir[3]) {
    k_ = &k;
    double *x = toloc_[0], *y = toloc_[1], *z = toloc_[2];
    for (int i = 0; i < 3; ++i) z[i] = front_normal[i];
    if (!Normalize(z)) return false;
    x[0] = up[1] * z[2] - up[2] * z[1];  // SDcompXform(): x = up x z
    x[1] = up[2] * z[0] - up[0] * z[2];
    x[2] = up[0] * z[1] - up[1] * z[0];
    if (!Normalize(x)) return false;
    y[0] = z[1] * x[2] - z[2] * x[1];
    y[1] = z[2] * x[0] - z[0] * x[2];
    y[2] = z[0] * x[1] - z[1] * x[0];
    const double back[3] = {-ray_dir[0], -ray_dir[1], -ray_dir[2]};
    ToLocal(back, vray_);
    double lo, hi;
    k.SizeMinMax(vray_, &lo, &hi);
    sr_vpsa_[0] = std::sqrt(lo);
    sr_vpsa_[1] = std::sqrt(hi);
    return true;
}

void KlemsHit::ToLocal(const double w[3], double l[3]) const {
    for (int i = 0; i < 3; ++i) l[i] = Dot(toloc_[i], w);
    Normalize(l);
}

void KlemsHit::ToWorld(const double l[3], double w[3]) const {
    for (int i = 0; i < 3; ++i)
        w[i] = toloc_[0][i] * l[0] + toloc_[1][i] * l[1] + toloc_[2][i] * l[2];
    Normalize(w);
}

void KlemsHit::Jitter(double size, double specular_jitter, double u, double v,
                      double out[3]) const {
    for (int i = 0; i < 3; ++i) out[i] = vray_[i];
    if (specular_jitter < 1.) size *= specular_jitter;
    if (size <= 1e-6) return;
    out[0] += size * (.5 - u);
    out[1] += size * (.5 - v);
    Normalize(out);
}

bool KlemsHit::DirectSpecular(const double source_dir[3], double specular_jitter, double weight,
                              const std::function<double()> &uniform, double *value) const {
    const KlemsScattering &k = *k_;
    *value = 0;
    double vsrc[3];
    ToLocal(source_dir, vsrc);
    const bool src_front = vsrc[2] > 0, view_front = vray_[2] > 0;
    double lambertian;  // the diffuse part, which direct() counts apart
    if (src_front == view_front) {
        if (!k.Reflection(view_front)) return false;
        lambertian = k.ReflectionLambertian(view_front);
    } else {
        if (!k.HasTransmission()) return false;
        lambertian = k.TransmissionLambertian(view_front);
    }
    const double diffuse = lambertian > 1e-6 ? lambertian / M_PI : 0.;
    const double tomega = k.SizeMin(vray_, vsrc);
    const double tsr = std::sqrt(tomega);
    int nsamp = 1;
    if (tsr > 0) nsamp = std::max(1, static_cast<int>(4. * specular_jitter * weight + .5));
    double sum = 0;
    int count = 0;
    for (int i = nsamp; i--;) {
        double vjit[3];
        const double u = uniform(), v = uniform();
        Jitter(tsr, specular_jitter, u, v, vjit);
        const double f = k.Eval(vjit, vsrc);
        if (f - diffuse <= 1e-6) continue;                   // no non-diffuse part
        if (k.SizeMin(vjit, vsrc) < .12 * tomega) continue;  // a finer patch: not safe to include
        sum += f;
        ++count;
    }
    if (!count) return false;
    *value = std::max(0., sum / count - diffuse);
    return true;
}

}  // namespace dayflux
