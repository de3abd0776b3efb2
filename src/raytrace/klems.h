// A Klems BSDF as the BSDF material traces it: RADIANCE's BSDF library calls (SDevalBSDF,
// SDdirectHemi, SDsizeBSDF, SDsampComponent on matrix data) over LoadKlemsBsdf()'s matrices.
// Directions are in the BSDF's local frame (z along the surface's front normal) and point away
// from the surface, toward where light comes from or goes to.
#pragma once

#include <functional>
#include <vector>

#include "matrix/bsdf_xml.h"

namespace dayflux {

class KlemsScattering {
  public:
    explicit KlemsScattering(const KlemsBsdf &data);

    // One of the four matrices, with what RADIANCE's SDMat keeps beside it: the side each basis
    // lies on and, per incident patch (and per outgoing patch, for reciprocity), the cumulative
    // distribution of BSDF x projected solid angle.
    // AngleBasis::IndexOf() and ProjectedSolidAngle() with the ring bounds' cosines and the
    // patches' projected solid angles tabulated: they run for every source at every hit.
    struct BasisTable {
        std::vector<double> cos_bounds, ohm;
        std::vector<int> first, nphis;
        void Set(const AngleBasis &b);
        int IndexOf(const double w[3]) const;
        double ProjSA(int i) const { return i < 0 ? -1. : ohm[i]; }
    };

    struct Part {
        KlemsComponent data;
        BasisTable in_table, out_table;
        bool in_front = true, out_front = true;  // fi/bi and fo/bo in bsdf_m.c
        std::vector<std::vector<double>> cdf, reverse_cdf;
        bool present() const { return data.present(); }
        int InIndex(const double v[3]) const;
        int OutIndex(const double v[3]) const;
        double InProjSA(int i) const { return in_table.ProjSA(i); }
        double OutProjSA(int o) const { return out_table.ProjSA(o); }
        double Value(int o, int i) const {
            return data.values[static_cast<size_t>(o) * data.in.Size() + i];
        }
    };

    const Part &rf() const { return rf_; }
    const Part &rb() const { return rb_; }
    const Part &tf() const { return tf_; }
    const Part &tb() const { return tb_; }
    bool HasTransmission() const { return tf_.present() || tb_.present(); }
    // Lambertian parts as hemispherical totals (cieY).
    double ReflectionLambertian(bool front) const { return front ? r_lamb_front_ : r_lamb_back_; }
    double TransmissionLambertian(bool front) const { return front ? t_lamb_front_ : t_lamb_back_; }
    // The transmission matrix serving rays arriving on a side (the other side's, reciprocally,
    // where that side has none); null if none.
    const Part *Transmission(bool front) const;
    const Part *Reflection(bool front) const;

    // SDevalBSDF: the BSDF (1/sr) for light between in and out, Lambertian part included.
    double Eval(const double in[3], const double out[3]) const;
    // SDdirectHemi for the non-diffuse part of reflection or transmission.
    double SpecularHemi(const double in[3], bool transmission) const;
    // SDsizeBSDF with SDqueryMin+SDqueryMax for one direction, SDqueryMin for a pair.
    void SizeMinMax(const double v[3], double *min, double *max) const;
    double SizeMin(const double v1[3], const double v2[3]) const;
    // SDsampComponent: the part's hemispherical total for `in`, and `out` drawn from its
    // distribution (rand picks the patch, u and v the place in it). Returns 0 (and leaves out)
    // when there is nothing to sample.
    static double Sample(const Part &p, const double in[3], double rand, double u, double v,
                         double out[3]);

  private:
    void Prepare(Part *p, bool in_front, bool out_front);
    void QueryProjSA(const Part &p, const double v1[3], const double v2[3], bool minmax,
                     double psa[2]) const;

    Part rf_, rb_, tf_, tb_;
    double r_lamb_front_, r_lamb_back_, t_lamb_front_, t_lamb_back_;
};

// What m_bsdf() sets up where a ray meets a BSDF surface: the local frame from the front normal
// and the up vector, the view direction in it, and the BSDF's resolution there.
class KlemsHit {
  public:
    // False (with the frame unset) when the up vector is parallel to the normal.
    bool Set(const KlemsScattering &k, const double front_normal[3], const double up[3],
             const double ray_dir[3]);
    const double *View() const { return vray_; }          // toward where the ray came from
    double ResolutionMin() const { return sr_vpsa_[0]; }  // sqrt of projected solid angles
    double ResolutionMax() const { return sr_vpsa_[1]; }
    void ToLocal(const double world[3], double local[3]) const;
    void ToWorld(const double local[3], double world[3]) const;
    // bsdf_jitter(): the view direction moved within +-size/2 (times -ss below 1).
    void Jitter(double size, double specular_jitter, double u, double v, double out[3]) const;
    // direct_specular_OK(): the non-diffuse BSDF toward a source direction (world), averaged
    // over 4 x ss x weight jittered views; false when there is none to add.
    bool DirectSpecular(const double source_dir[3], double specular_jitter, double weight,
                        const std::function<double()> &uniform, double *value) const;

  private:
    const KlemsScattering *k_ = nullptr;
    double toloc_[3][3];
    double vray_[3];
    double sr_vpsa_[2];
};

}  // namespace dayflux
