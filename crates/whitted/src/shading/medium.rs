//! The media a refracted ray is inside, so that Snell's law gets the right
//! ratio of indices at every surface it crosses: entering an object pushes
//! its material, leaving pops it, and the innermost medium is the one the
//! ray travels in. Nested dielectrics (an air bubble in glass) thus refract
//! correctly; overlapping ones follow the last-entered rule.

use crate::world::MaterialId;

/// The media a ray is inside, innermost last: the materials of the objects
/// it has entered, with their indices of refraction. Keyed by the material
/// filling the solid (`Surface::medium`: a CSG object's is one for all its
/// children), so a closed mesh of many triangles is one medium, and two
/// overlapping objects of the same material are one medium too. The innermost entry is the
/// medium the ray travels in. Fixed capacity (eight nested media; deeper
/// nesting is not recorded): no allocation per ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct MediumStack {
    entries: [(u32, f64); Self::CAPACITY],
    len: usize,
}

impl MediumStack {
    const CAPACITY: usize = 8;

    /// The index of refraction the ray travels in (1 outside everything).
    pub fn ior(&self) -> f64 {
        if self.len == 0 {
            1.0
        } else {
            self.entries[self.len - 1].1
        }
    }

    /// True when the ray is inside an object of `material`.
    pub fn contains(&self, material: MaterialId) -> bool {
        self.entries[..self.len]
            .iter()
            .any(|&(m, _)| m == material.0)
    }

    /// The stack after entering an object of `material`.
    pub fn entered(mut self, material: MaterialId, ior: f64) -> Self {
        if self.len < Self::CAPACITY {
            self.entries[self.len] = (material.0, ior);
            self.len += 1;
        }
        self
    }

    /// The stack after leaving an object of `material` (its innermost
    /// entry; unchanged if the ray was not known to be inside it).
    pub fn left(mut self, material: MaterialId) -> Self {
        if let Some(i) = self.entries[..self.len]
            .iter()
            .rposition(|&(m, _)| m == material.0)
        {
            self.entries.copy_within(i + 1..self.len, i);
            self.len -= 1;
        }
        self
    }
}

/// What a ray crossing a surface goes from and to.
#[derive(Clone, Copy, Debug)]
pub struct Crossing<'m> {
    /// Index of refraction on the incoming side.
    pub n_from: f64,
    /// Index of refraction on the far side.
    pub n_to: f64,
    /// The media before the surface.
    before: &'m MediumStack,
    /// The object's material, its index of refraction, and whether the
    /// ray enters it.
    object: (MaterialId, f64, bool),
}

impl Crossing<'_> {
    /// The media of a ray that goes through. Made only when one does: most
    /// crossings only reflect, and a copy of the stack is 136 bytes.
    pub fn after(&self) -> MediumStack {
        match self.object {
            (material, ior, true) => self.before.entered(material, ior),
            (material, _, false) => self.before.left(material),
        }
    }
}

impl MediumStack {
    /// Crossing the surface of an object of `material` (index `ior`),
    /// `entering` it or leaving it.
    pub fn cross(&self, material: MaterialId, ior: f64, entering: bool) -> Crossing<'_> {
        let object = (material, ior, entering);
        if entering {
            return Crossing {
                n_from: self.ior(),
                n_to: ior,
                before: self,
                object,
            };
        }
        // Leaving an object that is not the innermost medium changes nothing
        // for the ray; leaving one the stack does not know (the ray started
        // inside it) goes from that object's material.
        let n_from = if self.contains(material) {
            self.ior()
        } else {
            ior
        };
        Crossing {
            n_from,
            n_to: self.ior_after_leaving(material),
            before: self,
            object,
        }
    }

    /// [`MediumStack::ior`] of [`MediumStack::left`] without making it:
    /// only leaving the innermost medium changes it.
    fn ior_after_leaving(&self, material: MaterialId) -> f64 {
        let innermost = self.len.checked_sub(1);
        match self.entries[..self.len]
            .iter()
            .rposition(|&(m, _)| m == material.0)
        {
            Some(i) if Some(i) == innermost => match i.checked_sub(1) {
                Some(below) => self.entries[below].1,
                None => 1.0,
            },
            _ => self.ior(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medium_stack_tracks_nested_objects() {
        let glass = MaterialId(1);
        let water = MaterialId(2);
        let s = MediumStack::default();
        assert_eq!(s.ior(), 1.0);
        let s = s.entered(glass, 1.5);
        let s = s.entered(water, 1.33);
        assert_eq!(s.ior(), 1.33);
        let s = s.left(water);
        assert_eq!(s.ior(), 1.5);
        assert_eq!(s.left(MaterialId(9)).ior(), 1.5);
        assert_eq!(s.left(glass).ior(), 1.0);
    }

    #[test]
    fn the_index_beyond_is_the_one_of_the_media_after_the_crossing() {
        // Every stack of up to four media out of three materials (some
        // repeated), crossed each way at each material.
        let iors = [1.5, 1.33, 2.4];
        let mut stacks = vec![MediumStack::default()];
        for _ in 0..4 {
            let deeper: Vec<MediumStack> = stacks
                .iter()
                .flat_map(|s| (0..3).map(move |m| s.entered(MaterialId(m), iors[m as usize])))
                .collect();
            stacks.extend(deeper);
        }
        for stack in &stacks {
            for m in 0..4 {
                let ior = iors.get(m as usize).copied().unwrap_or(1.1);
                for entering in [true, false] {
                    let crossing = stack.cross(MaterialId(m), ior, entering);
                    assert_eq!(
                        crossing.n_to.to_bits(),
                        crossing.after().ior().to_bits(),
                        "{stack:?} material {m} entering {entering}"
                    );
                }
            }
        }
    }

    #[test]
    fn crossings_refract_only_where_the_medium_really_changes() {
        let (glass, bubble) = (MaterialId(1), MaterialId(2));
        let air = MediumStack::default();
        let into_glass = air.cross(glass, 1.5, true);
        assert_eq!((into_glass.n_from, into_glass.n_to), (1.0, 1.5));
        let in_glass = into_glass.after();
        let out_of_glass = in_glass.cross(glass, 1.5, false);
        assert_eq!((out_of_glass.n_from, out_of_glass.n_to), (1.5, 1.0));
        // Entering an overlapping ior-1 object from air, then the glass, then
        // leaving the first object while still in the glass: no interface.
        let in_both = air
            .cross(bubble, 1.0, true)
            .after()
            .cross(glass, 1.5, true)
            .after();
        let leave_outer = in_both.cross(bubble, 1.0, false);
        assert_eq!((leave_outer.n_from, leave_outer.n_to), (1.5, 1.5));
        // A ray that started inside the glass leaves it into air.
        let unknown = air.cross(glass, 1.5, false);
        assert_eq!((unknown.n_from, unknown.n_to), (1.5, 1.0));
    }

    #[test]
    fn medium_stack_leaving_an_outer_object_keeps_the_inner_one() {
        let s = MediumStack::default()
            .entered(MaterialId(1), 1.5)
            .entered(MaterialId(2), 1.33)
            .left(MaterialId(1));
        assert_eq!(s.ior(), 1.33);
        assert_eq!(s.left(MaterialId(2)).ior(), 1.0);
    }
}
