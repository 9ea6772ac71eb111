//! An orthonormal frame `(s, t, n)`: the shading frame a BSDF is evaluated in.

use glam::Vec3;

/// A right-handed orthonormal basis; `n` is the shading normal (local `z`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent (local `x`).
    pub s: Vec3,
    /// Second tangent (local `y`), `n × s`.
    pub t: Vec3,
    /// Normal (local `z`).
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit vector `n`, continuous in `n` except across `n.z = 0` (Duff et al.,
    /// "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017).
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// A world direction in local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// A local direction in world coordinates.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }

    /// The frame rebuilt around a tilted normal given in this frame's local coordinates (a unit
    /// vector with `z > 0`): `n' = to_world(local_n)`, `s'` is `s` made orthogonal to `n'`
    /// (Gram–Schmidt, so the tangent turns with the facet rather than jumping), `t' = n' × s'`.
    pub fn tilted(&self, local_n: Vec3) -> Frame {
        // An untilted normal leaves the frame exactly as it is (renormalising would round it, and
        // a 0° facet bump must render as no bump, bit for bit).
        if local_n == Vec3::Z {
            return *self;
        }
        let n = self.to_world(local_n).normalize();
        let s = self.s - n * n.dot(self.s);
        if s.length_squared() < 1e-8 || !n.is_finite() {
            return if n.is_finite() {
                Frame::from_normal(n)
            } else {
                *self
            };
        }
        let s = s.normalize();
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn an_untilted_normal_keeps_the_frame_bit_for_bit() {
        for k in 0..1000 {
            let a = k as f32 * 0.618;
            let n = Vec3::new(a.sin() * 0.7, a.cos(), (3.0 * a).sin() * 0.4).normalize();
            let f = Frame::from_normal(n);
            assert_eq!(f.tilted(Vec3::Z), f);
        }
    }
    use super::*;

    fn orthonormal(f: &Frame) {
        for (a, b) in [(f.s, f.t), (f.t, f.n), (f.n, f.s)] {
            assert!(a.dot(b).abs() < 1e-5, "{f:?}");
        }
        for v in [f.s, f.t, f.n] {
            assert!((v.length() - 1.0).abs() < 1e-5, "{f:?}");
        }
        assert!(
            (f.s.cross(f.t) - f.n).length() < 1e-5,
            "right-handed: {f:?}"
        );
    }

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(1e-8, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            orthonormal(&f);
            let v = Vec3::new(0.2, -0.5, 0.7).normalize();
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-5);
        }
    }

    #[test]
    fn tilted_frame_keeps_the_tangent_direction() {
        let f = Frame::from_normal(Vec3::new(0.1, 0.2, 0.97).normalize());
        let local = Vec3::new(0.3, 0.1, 0.95).normalize();
        let g = f.tilted(local);
        orthonormal(&g);
        assert!((g.n - f.to_world(local)).length() < 1e-5);
        assert!(
            g.s.dot(f.s) > 0.9,
            "tangent turned too far: {}",
            g.s.dot(f.s)
        );
        // No tilt: the same frame.
        let h = f.tilted(Vec3::Z);
        assert!((h.s - f.s).length() < 1e-5 && (h.n - f.n).length() < 1e-5);
        // A tilt onto the old tangent still gives a frame.
        orthonormal(&f.tilted(Vec3::X));
    }
}
