//! Map trees with effects switched off, for the accuracy knobs (docs/design.md §9): the glitter overlay,
//! the stochastic switch bands and the facet bump. The rewrite happens once, when the world is
//! built, so a switched-off effect costs nothing per lookup.

use super::map::{Map, MapNode};

/// Which map effects to keep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MapEffects {
    /// `Overlay` nodes (off: each shows only its `under` map).
    pub overlay: bool,
    /// Stochastic bands of `Switch` nodes (off: switches are hard, `blend = 0`).
    pub blend: bool,
    /// Facet bumps of Voronoi nodes (off: no facet normals).
    pub bump: bool,
}

impl Map {
    /// This tree with the effects `keep` leaves out removed. Node indices do not change: an
    /// `Overlay` is replaced by a copy of its `under` node (whose children come earlier still), and
    /// only where `under` is opaque everywhere, so the root stays opaque.
    pub fn with_effects(&self, keep: MapEffects) -> Map {
        let mut map = self.clone();
        for i in 0..map.nodes.len() {
            match map.nodes[i] {
                MapNode::Overlay { under, .. }
                    if !keep.overlay && !self.may_be_transparent(under) =>
                {
                    map.nodes[i] = map.nodes[under as usize];
                }
                MapNode::Switch { ref mut blend, .. } if !keep.blend => *blend = 0.0,
                MapNode::Voronoi(ref mut v) if !keep.bump => v.bump = None,
                _ => {}
            }
        }
        map
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::FieldNode;
    use glam::Vec3;

    const ALL: MapEffects = MapEffects {
        overlay: true,
        blend: true,
        bump: true,
    };

    /// Materials 0–3: a sparse glitter Voronoi (material 2) over a dense one (0 or 1), both under
    /// a constant switch (0, below its threshold 0.1, inside its band of 0.4) whose upper stop is
    /// material 3.
    fn fixture() -> Map {
        crate::texture::fixtures::glitter_under_switch(FieldNode::Constant(0.0), 0.1, 0.4)
    }

    fn points() -> impl Iterator<Item = (Vec3, f32)> {
        (0..4000).map(|i| {
            let p = Vec3::new(i as f32 * 0.0137, (i % 97) as f32 * 0.031, 0.2);
            (p, ((i * 7919) % 1000) as f32 / 1000.0)
        })
    }

    #[test]
    fn keeping_everything_is_the_same_tree() {
        let map = fixture();
        assert_eq!(map.with_effects(ALL), map);
    }

    #[test]
    fn switched_off_effects_leave_the_tree() {
        let map = fixture();
        // The constant field 0 lies inside the band (0.1 ± 0.2): both stops occur.
        let seen = |m: &Map| {
            let mut counts = [0usize; 4];
            let mut facets = 0;
            for (p, u) in points() {
                let hit = m.lookup(p, u);
                counts[hit.material as usize] += 1;
                facets += usize::from(hit.facet.is_some());
            }
            (counts, facets)
        };
        let (all, facets) = seen(&map);
        assert!(all.iter().all(|&c| c > 100), "{all:?}");
        assert!(facets > 0);

        let hard = map.with_effects(MapEffects {
            blend: false,
            ..ALL
        });
        let (counts, _) = seen(&hard);
        assert_eq!(
            counts[3], 0,
            "a hard switch below its threshold: {counts:?}"
        );

        let plain = map.with_effects(MapEffects {
            overlay: false,
            ..ALL
        });
        let (counts, _) = seen(&plain);
        assert_eq!(counts[2], 0, "no glitter without the overlay: {counts:?}");
        assert!(counts[0] > 100 && counts[1] > 100 && counts[3] > 100);

        let flat = map.with_effects(MapEffects { bump: false, ..ALL });
        let (counts, facets) = seen(&flat);
        assert_eq!((counts, facets), (all, 0));
    }
}
