//! Compiles a body's platelet populations (`body.platelets`, [`super::platelets`]) into
//! [`Population`]s: their face materials under the body's IOR, orientation, seed, grid, and the
//! density modulation, a field compiled by the map compiler into a table of its own.

use super::map_compiler::Compiler;
use super::platelets::OrientationDesc;
use super::surface::FieldDesc;
use crate::bsdf::StackDesc;
use crate::geometry::Shape;
use crate::platelet::{Modulation, Orientation, Population};
use crate::sampler::hash_words;
use crate::scene::Stage;
use glam::Vec3;

impl Compiler<'_> {
    /// The body's platelet populations and the materials of their faces (each under the body's
    /// IOR), indexed from `body_index + 1`; errors recorded (`None` after one).
    #[allow(clippy::type_complexity)]
    pub(super) fn platelets(
        &mut self,
        desc: &crate::recipe::BodyDesc,
        body_index: u32,
        from: usize,
    ) -> Option<(Vec<Population>, Vec<(String, StackDesc)>)> {
        let r = self.recipe;
        let mut pops = vec![];
        let mut mats: Vec<(String, StackDesc)> = vec![];
        let mut ok = true;
        // Errors point into the population they are about: its entry, or its `density` value.
        let list = r.source.find_from(from, &["platelets", ":"]);
        for (k, p) in desc.platelets.iter().enumerate() {
            let at = list.and_then(|l| r.source.nth_element(l, k)).or(list);
            let entry_list = at.and_then(|a| r.source.find_from(a, &["entries", ":"]));
            let mut entries = vec![];
            let total: f32 = p.entries.iter().map(|e| e.0).sum();
            let mut acc = 0.0;
            for (j, e) in p.entries.iter().enumerate() {
                let name = &e.1;
                let quoted = format!("{name:?}");
                let pos = entry_list
                    .and_then(|l| r.source.nth_element(l, j))
                    .and_then(|entry| r.source.find_from(entry, &[&quoted]))
                    .or(at);
                let stack = match r.library.stack(name) {
                    Ok(mut s) => {
                        s.outside_ior = desc.ior;
                        s
                    }
                    Err(_) => {
                        self.errors.push(r.source.error(
                            pos,
                            format!(
                                "body.platelets[{k}]: unknown material \"{name}\" (platelet faces \
                                 are the recipe's layered materials)"
                            ),
                        ));
                        ok = false;
                        continue;
                    }
                };
                if let Err(e) = crate::bsdf::layered::validate(&stack) {
                    self.errors.push(r.source.error(
                        pos,
                        format!("body.platelets[{k}]: material \"{name}\" under the body: {e}"),
                    ));
                    ok = false;
                    continue;
                }
                let index = match mats.iter().position(|(n, _)| n == name) {
                    Some(i) => i,
                    None => {
                        mats.push((name.clone(), stack));
                        mats.len() - 1
                    }
                };
                acc += e.0 / total;
                entries.push((acc, body_index + 1 + index as u32));
            }
            if let Some(last) = entries.last_mut() {
                last.0 = 1.0;
            }
            let orientation = match &p.orientation {
                OrientationDesc::Uniform => Orientation::Uniform,
                OrientationDesc::Aligned { axis, spread } => Orientation::Aligned {
                    axis: Vec3::new(axis.0, axis.1, axis.2).normalize(),
                    spread: spread.to_radians(),
                },
            };
            let seed = p
                .seed
                .unwrap_or_else(|| hash_words(&[r.content.seed, 0x706c_6174, k as u64]));
            // The position of key `key`'s value in this population.
            let value_of = |key: &str| {
                at.and_then(|a| r.source.find_from(a, &[key, ":"]))
                    .and_then(|k| {
                        let colon = k + r.source.text[k..].find(':')?;
                        Some(r.source.skip_blank(colon + 1))
                    })
                    .or(at)
            };
            let modulation = match &p.modulation {
                None => None,
                Some(field) => match self.modulation(field) {
                    Ok(m) => Some(m),
                    Err(msg) => {
                        self.errors.push(r.source.error(
                            value_of("modulation"),
                            format!("body.platelets[{k}]: {msg}"),
                        ));
                        ok = false;
                        None
                    }
                },
            };
            match Population::new(p.density, p.radius, orientation, entries, seed) {
                Some(pop) => pops.push(pop.with_modulation(modulation)),
                None => {
                    self.errors.push(r.source.error(
                        value_of("density"),
                        format!(
                            "body.platelets[{k}]: density {} with radius up to {} puts more than \
                             {} platelets in each cell of 2.2 × the largest radius on average: \
                             they would overlap; lower the density or the radius",
                            p.density,
                            p.radius.1,
                            crate::platelet::MAX_MEAN_PER_CELL
                        ),
                    ));
                    ok = false;
                }
            }
        }
        ok.then_some((pops, mats))
    }

    /// A population's density modulation: `field` compiled into a table of its own (default
    /// seeds continue the map tree's count; an explicit seed gives the same noise as the same
    /// seed in a `Switch`). An error when the field cannot exceed 0 anywhere.
    fn modulation(&mut self, field: &FieldDesc) -> Result<Modulation, String> {
        let map_fields = std::mem::take(&mut self.fields);
        let root = self.field(field);
        let table = std::mem::replace(&mut self.fields, map_fields);
        let m = Modulation::new(table, root)
            .ok_or_else(|| "modulation: internal: the field has no root".to_string())?;
        let (lo, hi) = m.bounds();
        if hi <= 0.0 {
            return Err(format!(
                "modulation: the field lies in {lo} ..= {hi}, never above 0: the density would \
                 be 0 everywhere (the factor is the field clamped to 0 ..= 1)"
            ));
        }
        Ok(m)
    }
}

impl Compiler<'_> {
    /// Records an error at the population when a walk of its explicit platelets could not cover
    /// the stone ([`crate::platelet::grid::check_span`]); only the analytic shapes, whose size is
    /// known here (a mesh is checked when the world is built).
    pub(super) fn check_platelet_span(&mut self, body: &crate::scene::Body, stage: &Stage) {
        if !stage.render.platelets_explicit || matches!(stage.shape, Shape::Mesh { .. }) {
            return;
        }
        let Ok(solid) = crate::geometry::Solid::new(&stage.shape) else {
            return;
        };
        let (lo, hi) = solid.bounds();
        if let Err(e) = crate::platelet::grid::check_span(&body.platelets, lo, hi) {
            let r = self.recipe;
            let list = r
                .source
                .find(&["body", ":"])
                .and_then(|b| r.source.find_from(b, &["platelets", ":"]));
            let at = list
                .and_then(|l| r.source.nth_element(l, e.population))
                .or(list);
            self.errors.push(r.source.error(at, e.to_string()));
        }
    }
}
