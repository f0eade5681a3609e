//! The inside test of a planar polygon, in the 2D plane of two coordinate
//! axes: the even-odd rule over its edges, with the edges of polygons with
//! many vertices sorted into horizontal bands so that a point is tested
//! against the few edges of its band rather than all of them.
//!
//! # Why the bands give exactly the answer of the full loop
//!
//! An edge changes the count for a point `(x, y)` only when one of its ends
//! is above `y` and the other is not, so only when `y` lies in the edge's
//! closed range `[y_low, y_high]`. Each edge is listed in every band from
//! `band_of(y_low)` to `band_of(y_high)`, and `band_of` is monotone (a
//! rounded subtraction, a product by a positive constant, a floor and a
//! clamp, each monotone), so `y_low ≤ y ≤ y_high` implies that the point's
//! band `band_of(y)` is among the edge's bands. The band's list therefore
//! holds every edge that can count, in the same order, and the same
//! arithmetic decides each one.
//!
//! The bands, the 2D points and the repeated first point (no modulo) make
//! the test cheaper than a loop over all edges of the 3D vertices
//! (measured, with the same picture to the bit: docs/performance-log.md,
//! figures moved out of doc comments).
//!
//! # Cells no edge comes near
//!
//! The same polygons get a grid over their bounding rectangle whose cells
//! that no edge comes near are marked inside or outside once, so that most
//! points of a large face are answered by one look-up. The mark is the
//! answer the loop gives at any point of the cell, for these reasons. Each
//! edge's box, grown by a margin `m`, is kept apart from each marked
//! cell's rectangle, grown by `m` too. A point the look-up places in a
//! cell lies within a few ulps (far less than `m`) of that rectangle, so
//! every edge is either wholly above or below it, and then counts for no
//! point there, or wholly beside it, more than `m` away. The crossing
//! test's rounding (a few ulps of the polygon's size) cannot turn the sign
//! of its side test across a distance of `m`, so for every edge the test
//! gives the exact answer at every such point. The exact even-odd count
//! is the same at all of them (a convex region no edge enters), so the
//! loop's answer is the same at the point and at the cell's middle, where
//! the mark was computed.

use crate::math::{DVec2, Vec3};

/// Polygons with at least this many edges get bands.
const BANDED_FROM: usize = 9;

/// The band lists hold about this many entries per edge at most: an outline
/// whose edges are tall (a comb, say) gets fewer bands, so that its lists
/// never grow with the square of the vertex count.
const ENTRIES_PER_EDGE: usize = 16;

/// Cells per side of the grid are four times the square root of the
/// number of edges, within these bounds.
const CELLS_PER_SIDE: (usize, usize) = (16, 128);

/// The margin kept between edges and marked cells, relative to the
/// outline's size: far above the rounding of the crossing test and of the
/// look-up, a few times 1e-16 of the size (both round differences of
/// coordinates, whose error is relative to the difference, not to the
/// coordinates).
const CELL_MARGIN: f64 = 1e-9;

/// The polygon's outline projected onto two coordinate axes.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Outline {
    /// The two kept axes.
    axes: [u8; 2],
    /// The vertices' coordinates along the two kept axes, in order, after
    /// the last one: edge `i` joins `points[i]` to `points[i + 1]`.
    points: Box<[DVec2]>,
    /// The edges by band, for polygons with many vertices.
    bands: Option<Bands>,
    /// The cells no edge comes near, for the same polygons.
    cells: Option<Cells>,
}

/// What a cell of [`Cells`] says of the points in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mark {
    /// An edge comes near: the loop decides.
    Edges,
    /// Every point is outside.
    Outside,
    /// Every point is inside.
    Inside,
}

/// A grid over an outline's bounding rectangle, each cell marked with the
/// answer for all its points where no edge comes near it (see the module
/// documentation).
#[derive(Clone, Debug, PartialEq)]
struct Cells {
    /// The bounding rectangle's lower corner.
    low: DVec2,
    /// Its upper corner.
    high: DVec2,
    /// Cells per unit along each axis.
    per_unit: DVec2,
    /// Cells per side.
    side: usize,
    /// The marks, row by row.
    marks: Box<[Mark]>,
}

impl Cells {
    /// The grid for the closed outline `points` (the first point repeated
    /// last), whose loop over the edges is `contains`; `None` when the
    /// outline spans no area or is not finite.
    fn new(points: &[DVec2], contains: impl Fn(DVec2) -> bool) -> Option<Self> {
        let (low, high) = points
            .iter()
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let size = high - low;
        if !(size.x > 0.0 && size.y > 0.0 && size.is_finite()) {
            return None;
        }
        let edges = points.len() - 1;
        let side =
            ((4.0 * (edges as f64).sqrt()) as usize).clamp(CELLS_PER_SIDE.0, CELLS_PER_SIDE.1);
        let per_unit = DVec2::splat(side as f64) / size;
        let margin = CELL_MARGIN * (size.x + size.y);
        // The cells whose rectangle, grown by `margin`, meets [a, b] grown
        // by `margin` (one more margin covers this computation's rounding).
        let span = |a: f64, b: f64, axis: usize| {
            let cell = |v: f64| {
                (((v - low[axis]) * per_unit[axis]).floor().max(0.0) as usize).min(side - 1)
            };
            cell(a - 3.0 * margin)..=cell(b + 3.0 * margin)
        };
        let mut marks = vec![Mark::Inside; side * side];
        for edge in points.windows(2) {
            let (lo, hi) = (edge[0].min(edge[1]), edge[0].max(edge[1]));
            for row in span(lo.y, hi.y, 1) {
                for column in span(lo.x, hi.x, 0) {
                    marks[row * side + column] = Mark::Edges;
                }
            }
        }
        for (i, mark) in marks.iter_mut().enumerate() {
            if *mark != Mark::Edges {
                let cell = DVec2::new((i % side) as f64 + 0.5, (i / side) as f64 + 0.5);
                *mark = if contains(low + cell / per_unit) {
                    Mark::Inside
                } else {
                    Mark::Outside
                };
            }
        }
        Some(Self {
            low,
            high,
            per_unit,
            side,
            marks: marks.into_boxed_slice(),
        })
    }

    /// Whether `p` is inside, if its cell says so for all its points.
    #[inline]
    fn look_up(&self, p: DVec2) -> Option<bool> {
        if !(p.x >= self.low.x && p.x <= self.high.x && p.y >= self.low.y && p.y <= self.high.y) {
            return None;
        }
        let cell = (p - self.low) * self.per_unit;
        let column = (cell.x as usize).min(self.side - 1);
        let row = (cell.y as usize).min(self.side - 1);
        match self.marks[row * self.side + column] {
            Mark::Edges => None,
            Mark::Outside => Some(false),
            Mark::Inside => Some(true),
        }
    }
}

/// The edges of an outline sorted into horizontal bands of equal height:
/// band `k` lists, as `(start, end)` offsets into `edges`, the edges whose
/// vertical range meets it.
#[derive(Clone, Debug, PartialEq)]
struct Bands {
    /// The bottom of the first band.
    bottom: f64,
    /// Bands per unit of height.
    per_unit: f64,
    /// `edges[starts[k]..starts[k + 1]]` are band `k`'s edges.
    starts: Box<[u32]>,
    /// Edge indices, as in [`Outline::points`].
    edges: Box<[u32]>,
}

impl Bands {
    /// Bands for the closed outline `points` (the first point repeated
    /// last): one per edge, or fewer when the edges are tall,
    /// so that the lists hold at most [`ENTRIES_PER_EDGE`] entries per edge
    /// (plus the two bands each edge's ends may straddle).
    fn new(points: &[DVec2]) -> Self {
        let count = points.len() - 1;
        let edge = |i: usize| {
            let (a, b) = (points[i].y, points[i + 1].y);
            (a.min(b), a.max(b))
        };
        let (bottom, top) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.y), hi.max(p.y))
            });
        let height = top - bottom;
        // The mean number of edges a horizontal line meets: a band list
        // holds about that many edges per band.
        let crossings: f64 = (0..count)
            .map(|i| {
                let (low, high) = edge(i);
                high - low
            })
            .sum::<f64>()
            / height;
        let band_count = if height > 0.0 && height.is_finite() && crossings.is_finite() {
            (ENTRIES_PER_EDGE as f64 * count as f64 / crossings.max(1.0)).clamp(1.0, count as f64)
                as usize
        } else {
            1
        };
        let mut bands = Self {
            bottom,
            per_unit: if band_count > 1 {
                band_count as f64 / height
            } else {
                0.0
            },
            starts: vec![0; band_count + 1].into_boxed_slice(),
            edges: Box::new([]),
        };
        let ranges: Vec<(usize, usize)> = (0..count)
            .map(|i| {
                let (low, high) = edge(i);
                (bands.band_of(low), bands.band_of(high))
            })
            .collect();
        let mut sizes = vec![0u32; band_count];
        for &(first, last) in &ranges {
            for size in &mut sizes[first..=last] {
                *size += 1;
            }
        }
        let mut offset = 0;
        for (k, size) in sizes.iter().enumerate() {
            bands.starts[k] = offset;
            offset += size;
        }
        bands.starts[band_count] = offset;
        let mut edges = vec![0u32; offset as usize];
        let mut fill: Vec<u32> = bands.starts[..band_count].to_vec();
        for (edge, &(first, last)) in ranges.iter().enumerate() {
            for slot in &mut fill[first..=last] {
                edges[*slot as usize] = edge as u32;
                *slot += 1;
            }
        }
        bands.edges = edges.into_boxed_slice();
        bands
    }

    /// The band holding height `y`, clamped to the existing bands.
    fn band_of(&self, y: f64) -> usize {
        let last = self.starts.len() - 2;
        (((y - self.bottom) * self.per_unit).max(0.0) as usize).min(last)
    }

    /// The edges whose vertical range may hold `y`.
    fn edges_at(&self, y: f64) -> &[u32] {
        let k = self.band_of(y);
        &self.edges[self.starts[k] as usize..self.starts[k + 1] as usize]
    }
}

impl Outline {
    /// The outline of `vertices` seen along the axis that is neither of
    /// `axes`.
    pub(super) fn new(vertices: &[Vec3], axes: [usize; 2]) -> Self {
        let points: Box<[DVec2]> = vertices
            .last()
            .into_iter()
            .chain(vertices)
            .map(|v| DVec2::new(v[axes[0]], v[axes[1]]))
            .collect();
        let bands = (vertices.len() >= BANDED_FROM).then(|| Bands::new(&points));
        let mut outline = Self {
            axes: axes.map(|a| a as u8),
            points,
            bands,
            cells: None,
        };
        if outline.bands.is_some() {
            outline.cells = Cells::new(&outline.points, |p| outline.edges_contain(p));
        }
        outline
    }

    /// The two kept axes.
    pub(super) fn axes(&self) -> [usize; 2] {
        self.axes.map(usize::from)
    }

    /// True when `p`, a point in the polygon's plane, is inside.
    pub(super) fn contains(&self, p: Vec3) -> bool {
        let [ax, ay] = self.axes();
        self.contains_2d(DVec2::new(p[ax], p[ay]))
    }

    /// True when `p`, on the kept axes, is inside by the even-odd rule.
    ///
    /// Counts the edges crossed by a ray from `p` along the first axis. Each
    /// edge is half-open in the second axis (one end strictly above the
    /// point, the other at or below), so a vertex level with the point is
    /// counted exactly once; the side test is computed from the edge's lower
    /// end whatever the vertex order, so a point on an edge shared by two
    /// polygons of the same plane is inside exactly one of them.
    fn contains_2d(&self, p: DVec2) -> bool {
        if let Some(inside) = self.cells.as_ref().and_then(|cells| cells.look_up(p)) {
            return inside;
        }
        self.edges_contain(p)
    }

    /// [`Self::contains_2d`] by the edges alone: those of the point's
    /// band, or all of them.
    fn edges_contain(&self, p: DVec2) -> bool {
        match &self.bands {
            Some(bands) => bands.edges_at(p.y).iter().fold(false, |inside, &i| {
                let i = i as usize;
                inside ^ crosses(self.points[i], self.points[i + 1], p)
            }),
            None => self
                .points
                .windows(2)
                .fold(false, |inside, edge| inside ^ crosses(edge[0], edge[1], p)),
        }
    }
}

/// True when the edge from `a` to `b` is crossed by the ray from `p`
/// (see [`Outline::contains`]).
#[inline]
fn crosses(a: DVec2, b: DVec2, p: DVec2) -> bool {
    if (b.y > p.y) == (a.y > p.y) {
        return false;
    }
    let (low, high) = if b.y > a.y { (a, b) } else { (b, a) };
    (high.x - low.x) * (p.y - low.y) - (high.y - low.y) * (p.x - low.x) > 0.0
}

#[cfg(test)]
mod tests {
    use std::f64::consts::TAU;

    use super::*;
    use crate::math::random::Rng;

    /// The outline of `points` (in the plane z = 0) without bands.
    fn unbanded(points: &[DVec2]) -> Outline {
        Outline {
            bands: None,
            cells: None,
            ..Outline::new(&lift(points), [0, 1])
        }
    }

    fn star(teeth: usize, rng: &mut Rng) -> Vec<DVec2> {
        (0..2 * teeth)
            .map(|k| {
                let angle = TAU * k as f64 / (2 * teeth) as f64;
                let radius = if k % 2 == 0 {
                    1.0
                } else {
                    0.3 + 0.6 * rng.uniform()
                };
                radius * DVec2::new(angle.cos(), angle.sin())
            })
            .collect()
    }

    fn lift(points: &[DVec2]) -> Vec<Vec3> {
        points.iter().map(|p| Vec3::new(p.x, p.y, 0.0)).collect()
    }

    #[test]
    fn many_vertices_get_bands_and_few_do_not() {
        let mut rng = Rng::new(1);
        assert!(
            Outline::new(&lift(&star(72, &mut rng)), [0, 1])
                .bands
                .is_some()
        );
        let square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let square: Vec<DVec2> = square.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
        assert!(Outline::new(&lift(&square), [0, 1]).bands.is_none());
    }

    #[test]
    fn every_band_lists_each_edge_at_most_once_and_in_order() {
        let mut rng = Rng::new(2);
        let outline = Outline::new(&lift(&star(40, &mut rng)), [0, 1]);
        let bands = outline.bands.unwrap();
        for k in 0..bands.starts.len() - 1 {
            let edges = &bands.edges[bands.starts[k] as usize..bands.starts[k + 1] as usize];
            assert!(edges.windows(2).all(|w| w[0] < w[1]), "band {k}");
        }
    }

    #[test]
    fn banded_test_agrees_with_the_loop_over_all_edges() {
        let mut rng = Rng::new(3);
        for teeth in [5, 9, 72, 300] {
            let points = star(teeth, &mut rng);
            let banded = Outline::new(&lift(&points), [0, 1]);
            assert!(banded.bands.is_some());
            let reference = unbanded(&points);
            let check = |p: DVec2| {
                assert_eq!(
                    banded.contains_2d(p),
                    reference.contains_2d(p),
                    "{teeth} teeth at {p}"
                );
            };
            for _ in 0..20_000 {
                check(DVec2::new(
                    2.4 * rng.uniform() - 1.2,
                    2.4 * rng.uniform() - 1.2,
                ));
            }
            // Points level with every vertex and on every edge's ends, where
            // the half-open rule and the band borders matter most.
            for &v in &points {
                for dx in [-0.5, -1e-9, 0.0, 1e-9, 0.5] {
                    check(DVec2::new(v.x + dx, v.y));
                }
            }
        }
    }

    #[test]
    fn cells_answer_as_the_loop_over_all_edges() {
        let mut rng = Rng::new(6);
        // Stars and a gear, also small and far from the origin, where the
        // margin is set by the coordinates rather than the size.
        let gear: Vec<DVec2> = (0..144)
            .map(|k| {
                let angle = TAU * k as f64 / 144.0;
                let radius = if (k / 2) % 2 == 0 { 1.0 } else { 0.85 };
                radius * DVec2::new(angle.cos(), angle.sin())
            })
            .collect();
        // Each with the share of its cells that must be marked at least
        // (the stars' long slanted edges have boxes that cover most cells).
        let shapes = [
            (star(12, &mut rng), 0.0),
            (star(72, &mut rng), 0.0),
            (gear, 0.5),
        ];
        let placements = [(DVec2::ZERO, 1.0), (DVec2::new(1e5, -3e4), 1e-3)];
        for (points, share) in &shapes {
            for &(offset, scale) in &placements {
                let points: Vec<DVec2> = points.iter().map(|&p| offset + scale * p).collect();
                let outline = Outline::new(&lift(&points), [0, 1]);
                let reference = unbanded(&points);
                let cells = outline.cells.as_ref().expect("a banded outline has cells");
                let marked = cells.marks.iter().filter(|&&m| m != Mark::Edges).count();
                assert!(
                    marked as f64 >= share * cells.marks.len() as f64,
                    "{marked} of {} cells marked",
                    cells.marks.len()
                );
                let check = |p: DVec2| {
                    assert_eq!(
                        outline.contains_2d(p),
                        reference.contains_2d(p),
                        "{} points at {p}",
                        points.len()
                    );
                };
                let size = cells.high - cells.low;
                for _ in 0..20_000 {
                    check(cells.low - 0.1 * size + 1.2 * size * rng.uniform());
                }
                // On every cell border and a few ulps either side of it.
                for k in 0..=cells.side {
                    let border = cells.low + DVec2::splat(k as f64) / cells.per_unit;
                    for _ in 0..20 {
                        let along = cells.low + size * rng.uniform();
                        let ulps = rng.below(9) as i64 - 4;
                        let nudge = |v: f64| f64::from_bits((v.to_bits() as i64 + ulps) as u64);
                        check(DVec2::new(nudge(border.x), along.y));
                        check(DVec2::new(along.x, nudge(border.y)));
                    }
                }
                // Along every edge and just off it on either side.
                for edge in points
                    .windows(2)
                    .chain([[points[points.len() - 1], points[0]].as_slice()])
                {
                    let (a, b) = (edge[0], edge[1]);
                    let across = (b - a).perp().normalize();
                    for _ in 0..10 {
                        let on = a + (b - a) * rng.uniform();
                        for distance in [0.0, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3] {
                            check(on + distance * scale * across);
                            check(on - distance * scale * across);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn points_beyond_the_outline_or_nan_are_outside() {
        let mut rng = Rng::new(4);
        let outline = Outline::new(&lift(&star(72, &mut rng)), [0, 1]);
        for p in [
            DVec2::new(0.0, 5.0),
            DVec2::new(0.0, -5.0),
            DVec2::new(5.0, 0.0),
            DVec2::new(0.0, f64::INFINITY),
            DVec2::new(f64::NAN, 0.0),
            DVec2::new(0.0, f64::NAN),
        ] {
            assert!(!outline.contains_2d(p), "{p}");
        }
        assert!(outline.contains_2d(DVec2::new(0.0, 0.0)));
    }

    #[test]
    fn tall_edges_get_few_bands_and_the_lists_stay_linear_in_size() {
        // A comb of 500 teeth: half the edges span the whole height.
        let n = 2000;
        let comb: Vec<DVec2> = (0..n)
            .map(|k| DVec2::new(k as f64, if k % 4 < 2 { 0.0 } else { 10.0 }))
            .collect();
        let outline = Outline::new(&lift(&comb), [0, 1]);
        let bands = outline.bands.as_ref().unwrap();
        assert!(
            bands.edges.len() <= (ENTRIES_PER_EDGE + 2) * n,
            "{}",
            bands.edges.len()
        );
        let reference = unbanded(&comb);
        let mut rng = Rng::new(5);
        for _ in 0..2000 {
            let p = DVec2::new(2000.0 * rng.uniform(), 10.0 * rng.uniform());
            assert_eq!(outline.contains_2d(p), reference.contains_2d(p), "{p}");
        }
    }

    #[test]
    fn a_horizontal_outline_has_one_band_and_contains_nothing() {
        let flat: Vec<DVec2> = (0..12).map(|k| DVec2::new(k as f64, 0.0)).collect();
        let outline = Outline::new(&lift(&flat), [0, 1]);
        assert!(!outline.contains_2d(DVec2::new(3.5, 0.0)));
        assert!(!outline.contains_2d(DVec2::new(3.5, 1e-300)));
    }
}
