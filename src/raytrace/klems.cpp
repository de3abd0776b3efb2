#include "raytrace/klems.h"

#include <cmath>

namespace dayflux {

void KlemsScattering::BasisTable::Set(const AngleBasis &b) {
    cos_bounds.clear(), ohm.clear(), first.clear();
    nphis = b.nphis;
    for (double t : b.theta) cos_bounds.push_back(std::cos(M_PI / 180. * t));
    for (int i = 0; i < b.Size(); ++i) ohm.push_back(b.ProjectedSolidAngle(i));
    int n = 0;
    for (int p : nphis) first.push_back(n), n += p;
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
            p->cdf[i][o + 1] = p->cdf[i][o] + p->Value(o, i) * p->out_table.ohm[o];
    p->reverse_cdf.assign(nout, std::vector<double>(nin + 1, 0.));
    for (int o = 0; o < nout; ++o)
        for (int i = 0; i < nin; ++i)
            p->reverse_cdf[o][i + 1] = p->reverse_cdf[o][i] + p->Value(o, i) * p->in_table.ohm[i];
}

}  // namespace dayflux
