# flicker's BSDF as a Mitsuba 3 plugin (`gltf`): the glTF 2.0 metallic-roughness model of
# render/shaders/pt_bsdf.wgsl, f = c_diff / pi (1 - F(n.v)) (1 - F(n.l)) / (1 - F_avg)
# + F(v.h) D G2 / (4 |n.v| |n.l|), with c_diff = base (1 - metallic), Schlick's F between
# F0 = mix(0.04 specular, base, metallic) and F90 = mix(specular, 1, metallic),
# F_avg = F0 + (F90 - F0) / 21 (Schlick's cosine-weighted mean: the diffuse coupling of Shirley
# et al. 1997), GGX D with alpha = max(roughness^2, 1e-3) and Smith's height-correlated
# G2 = 1 / (1 + Lambda(v) + Lambda(l)).
# No stock Mitsuba BSDF is this model term for term: `principled` has Disney's retro-reflective
# diffuse and a Fresnel blended with the dielectric one, `roughconductor` the complex-IOR
# conductor Fresnel, and both the separable G1(v) G1(l); so the matrix renders it through this
# plugin. D, G1 and the sampling are Mitsuba's own (mi.MicrofacetDistribution, visible normals),
# G2 is formed from Mitsuba's G1 (Lambda = 1 / G1 - 1); lobe selection is a fixed split, not
# ours. Used by scripts/mitsuba_matrix.py and scripts/mitsuba_render.py (scalar variants).
import drjit as dr
import mitsuba as mi

MIN_ALPHA = 1.0e-3


class GltfBsdf(mi.BSDF):
    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        self.base = mi.Color3f(props['base_color'])
        self.metallic = min(max(float(props['metallic']), 0.0), 1.0)
        roughness = min(max(float(props['roughness']), 0.0), 1.0)
        specular = max(float(props['specular']), 0.0)
        self.alpha = max(roughness * roughness, MIN_ALPHA)
        self.c_diff = self.base * (1.0 - self.metallic)
        self.f0 = dr.lerp(mi.Color3f(0.04 * specular), self.base, self.metallic)
        self.f90 = specular + (1.0 - specular) * self.metallic
        self.distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.alpha, True)
        # Diffuse and specular lobes sampled half and half (only specular for a pure metal).
        self.p_spec = 1.0 if dr.max(self.c_diff) <= 0.0 else 0.5
        flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide
        self.m_flags = flags
        self.m_components = [flags]

    def fresnel(self, cos_theta):
        x = min(max(1.0 - cos_theta, 0.0), 1.0)
        return self.f0 + (mi.Color3f(self.f90) - self.f0) * (x ** 5)

    def f_cos(self, wi, wo):
        # Mitsuba's wi is flicker's wo (towards the viewer), Mitsuba's wo flicker's wi.
        cos_v, cos_l = mi.Frame3f.cos_theta(wi), mi.Frame3f.cos_theta(wo)
        if cos_v <= 0.0 or cos_l <= 0.0:
            return mi.Color3f(0.0)
        h = dr.normalize(wi + wo)
        f = self.fresnel(max(dr.dot(wi, h), 0.0))
        g1v, g1l = self.distr.smith_g1(wi, h), self.distr.smith_g1(wo, h)
        spec = mi.Color3f(0.0)
        if g1v > 0.0 and g1l > 0.0:
            g2 = 1.0 / (1.0 / g1v + 1.0 / g1l - 1.0)
            spec = f * (self.distr.eval(h) * g2 / (4.0 * cos_v * cos_l))
        f_avg = self.f0 + (mi.Color3f(self.f90) - self.f0) * (1.0 / 21.0)
        coupling = (mi.Color3f(1.0) - self.fresnel(cos_v)) * (mi.Color3f(1.0) - self.fresnel(cos_l)) \
            / dr.maximum(mi.Color3f(1.0) - f_avg, mi.Color3f(1.0e-6))
        return (coupling * self.c_diff * dr.inv_pi + spec) * cos_l

    def pdf_of(self, wi, wo):
        cos_v, cos_l = mi.Frame3f.cos_theta(wi), mi.Frame3f.cos_theta(wo)
        if cos_v <= 0.0 or cos_l <= 0.0:
            return 0.0
        h = dr.normalize(wi + wo)
        d = dr.dot(wo, h)
        spec = self.distr.pdf(wi, h) / (4.0 * d) if d > 0.0 else 0.0
        return self.p_spec * spec + (1.0 - self.p_spec) * cos_l * dr.inv_pi

    def sample(self, ctx, si, sample1, sample2, active=True):
        bs = mi.BSDFSample3f()
        wi = si.wi
        if mi.Frame3f.cos_theta(wi) <= 0.0:
            return bs, mi.Color3f(0.0)
        if sample1 < self.p_spec:
            m, _ = self.distr.sample(wi, sample2)
            wo = mi.reflect(wi, m)
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
        else:
            wo = mi.warp.square_to_cosine_hemisphere(sample2)
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.DiffuseReflection)
        bs.wo = wo
        bs.eta = 1.0
        bs.sampled_component = mi.UInt32(0)
        bs.pdf = self.pdf_of(wi, wo)
        if bs.pdf <= 0.0:
            return bs, mi.Color3f(0.0)
        return bs, self.f_cos(wi, wo) / bs.pdf

    def eval(self, ctx, si, wo, active=True):
        return self.f_cos(si.wi, wo)

    def pdf(self, ctx, si, wo, active=True):
        return self.pdf_of(si.wi, wo)

    def eval_pdf(self, ctx, si, wo, active=True):
        return self.f_cos(si.wi, wo), self.pdf_of(si.wi, wo)

    def to_string(self):
        return f'GltfBsdf[alpha={self.alpha}, metallic={self.metallic}]'


def register():
    mi.register_bsdf('gltf', lambda props: GltfBsdf(props))
