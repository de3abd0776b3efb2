// A Klems BSDF as the estimator core samples it (raytrace/core/klems.inl): LoadKlemsBsdf()'s
// four matrices with what RADIANCE's SDMat keeps beside each, the side each basis lies on, the
// bases' ring bounds and patches' projected solid angles as tables, and per incident patch (and
// per outgoing patch, for reciprocity) the cumulative distribution of BSDF x projected solid
// angle. raytrace/packing.h lays it out for the core.
#pragma once

#include <vector>

#include "matrix/bsdf_xml.h"

namespace dayflux {

class KlemsScattering {
  public:
    explicit KlemsScattering(const KlemsBsdf &data);

    // AngleBasis::IndexOf()'s and ProjectedSolidAngle()'s numbers, tabulated: ring bounds'
    // cosines, patches' projected solid angles, each ring's first patch and azimuth count.
    struct BasisTable {
        std::vector<double> cos_bounds, ohm;
        std::vector<int> first, nphis;
        void Set(const AngleBasis &b);
    };

    struct Part {
        KlemsComponent data;
        BasisTable in_table, out_table;
        bool in_front = true, out_front = true;  // fi/bi and fo/bo in bsdf_m.c
        std::vector<std::vector<double>> cdf, reverse_cdf;
        bool present() const { return data.present(); }
        double Value(int o, int i) const {
            return data.values[static_cast<size_t>(o) * data.in.Size() + i];
        }
    };

    const Part &rf() const { return rf_; }
    const Part &rb() const { return rb_; }
    const Part &tf() const { return tf_; }
    const Part &tb() const { return tb_; }
    // Lambertian parts as hemispherical totals (cieY).
    double ReflectionLambertian(bool front) const { return front ? r_lamb_front_ : r_lamb_back_; }
    double TransmissionLambertian(bool front) const { return front ? t_lamb_front_ : t_lamb_back_; }

  private:
    void Prepare(Part *p, bool in_front, bool out_front);

    Part rf_, rb_, tf_, tb_;
    double r_lamb_front_, r_lamb_back_, t_lamb_front_, t_lamb_back_;
};

}  // namespace dayflux
