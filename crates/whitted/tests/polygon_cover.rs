//! Polygons cover the area inside their outline, whether written as NFF
//! `p` (a polygon), NFF `pp` (a patch, with vertex normals) or an OBJ face
//! (with texture coordinates, so vertices on edges get theirs): random
//! star-shaped and x-monotone concave polygons, and outlines that cross
//! themselves, at random orientations, checked on random rays against an
//! even-odd point-in-polygon oracle.

use std::fmt::Write;
use std::path::Path;

use whitted::math::random::Rng;
use whitted::math::{DVec2, Ray, Vec3};
use whitted::scene::{parse_nff, parse_obj};
use whitted::world::World;

const VIEW: &str = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.001\nresolution 8 8\n\
                    f 0.8 0.6 0.4 1 0 30 0 1\n";

/// A star-shaped polygon of `n` corners around the origin: sorted angles,
/// radii between 0.2 and 1 (deep notches make it concave).
fn star(rng: &mut Rng, n: usize) -> Vec<DVec2> {
    let mut angles: Vec<f64> = (0..n)
        .map(|_| rng.range(0.0, std::f64::consts::TAU))
        .collect();
    angles.sort_by(f64::total_cmp);
    angles
        .iter()
        .map(|&a| rng.range(0.2, 1.0) * DVec2::new(a.cos(), a.sin()))
        .collect()
}

/// A polygon monotone in x, not star-shaped in general: from (-1, 0) a top
/// chain to (1, 0) and a bottom chain back, both with deep random notches
/// (the top above y = 0, the bottom below, so the outline is simple).
fn monotone(rng: &mut Rng, n: usize) -> Vec<DVec2> {
    let inner = n - 2;
    let top = inner / 2;
    let bottom = inner - top;
    let mut xs = |count: usize| {
        let mut x: Vec<f64> = (0..count).map(|_| rng.range(-0.99, 0.99)).collect();
        x.sort_by(f64::total_cmp);
        x
    };
    let (top_x, bottom_x) = (xs(top), xs(bottom));
    let mut points = vec![DVec2::new(-1.0, 0.0)];
    points.extend(top_x.iter().map(|&x| DVec2::new(x, rng.range(0.02, 1.0))));
    points.push(DVec2::new(1.0, 0.0));
    points.extend(
        bottom_x
            .iter()
            .rev()
            .map(|&x| DVec2::new(x, -rng.range(0.02, 1.0))),
    );
    points
}

/// An outline through `n` random points of the unit disk in random order:
/// it crosses itself in general.
fn tangle(rng: &mut Rng, n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|_| {
            let angle = rng.range(0.0, std::f64::consts::TAU);
            rng.range(0.1, 1.0) * DVec2::new(angle.cos(), angle.sin())
        })
        .collect()
}

/// Even-odd point in polygon.
fn inside(outline: &[DVec2], p: DVec2) -> bool {
    let mut odd = false;
    for (i, &a) in outline.iter().enumerate() {
        let b = outline[(i + 1) % outline.len()];
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            odd = !odd;
        }
    }
    odd
}

/// Distance from `p` to the outline.
fn distance_to_outline(outline: &[DVec2], p: DVec2) -> f64 {
    (0..outline.len())
        .map(|i| {
            let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            (a + t * (b - a) - p).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// A random frame: an origin and two orthonormal axes spanning the plane.
fn frame(rng: &mut Rng) -> (Vec3, Vec3, Vec3) {
    let normal = rng.unit_vector();
    let helper = if normal.x.abs() < 0.9 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let u = normal.cross(helper).normalize();
    let v = normal.cross(u);
    (rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0)), u, v)
}

/// The NFF text of the polygon as `p` or as `pp` (random vertex normals).
fn nff(points: &[Vec3], patch: bool, rng: &mut Rng) -> String {
    let mut text = String::from(VIEW);
    writeln!(text, "{} {}", if patch { "pp" } else { "p" }, points.len()).unwrap();
    for p in points {
        write!(text, "{:?} {:?} {:?}", p.x, p.y, p.z).unwrap();
        if patch {
            let n = rng.unit_vector();
            write!(text, " {:?} {:?} {:?}", n.x, n.y, n.z).unwrap();
        }
        text.push('\n');
    }
    text
}

/// The OBJ text of the polygon as one face with texture coordinates.
fn obj(points: &[Vec3]) -> String {
    let mut text = String::new();
    for (i, p) in points.iter().enumerate() {
        writeln!(text, "v {:?} {:?} {:?}", p.x, p.y, p.z).unwrap();
        writeln!(text, "vt {} 0.5", i as f64 / points.len() as f64).unwrap();
    }
    text.push('f');
    for i in 1..=points.len() {
        write!(text, " {i}/{i}").unwrap();
    }
    text.push('\n');
    text
}

/// The objects of the polygon in each form: `p`, `pp` and an OBJ face.
fn forms(points: &[Vec3], rng: &mut Rng) -> Vec<(&'static str, whitted::Scene, String)> {
    let mut out = Vec::new();
    for (name, text) in [
        ("p", nff(points, false, rng)),
        ("pp", nff(points, true, rng)),
    ] {
        let scene = parse_nff(&text, Path::new("polygon.nff"))
            .unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        out.push((name, scene, text));
    }
    let text = obj(points);
    let loaded =
        parse_obj(&text, Path::new("polygon.obj")).unwrap_or_else(|e| panic!("obj: {e}\n{text}"));
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    out.push(("obj", loaded.scene, text));
    out
}

#[test]
fn p_pp_and_obj_polygons_cover_exactly_the_inside_of_their_outline() {
    let mut rng = Rng::new(22);
    let mut checked = 0;
    let mut hits = 0;
    for case in 0..180 {
        let n = 3 + (case % 38);
        let outline = match case % 3 {
            0 => star(&mut rng, n),
            1 => monotone(&mut rng, n.max(4)),
            _ => tangle(&mut rng, 4 + case % 9),
        };
        let (origin, u, v) = frame(&mut rng);
        let points: Vec<Vec3> = outline.iter().map(|q| origin + q.x * u + q.y * v).collect();
        for (form, scene, text) in forms(&points, &mut rng) {
            let world = World::new(&scene.objects);
            for _ in 0..200 {
                let target = rng.range(-1.1, 1.1) * u + rng.range(-1.1, 1.1) * v + origin;
                let eye = target + 5.0 * rng.unit_vector();
                let ray = Ray::new(eye, target - eye);
                // Where the ray meets the plane, in the outline's coordinates.
                let normal = u.cross(v);
                let t = (origin - eye).dot(normal) / (target - eye).dot(normal);
                let q = eye + t * (target - eye) - origin;
                let p = DVec2::new(q.dot(u), q.dot(v));
                if !t.is_finite() || t <= 0.0 || distance_to_outline(&outline, p) < 1e-9 {
                    continue;
                }
                let expected = inside(&outline, p);
                let hit = world.intersect(&ray);
                assert_eq!(
                    hit.is_some(),
                    expected,
                    "case {case} ({form}), {} corners, point {p} at distance {} from the outline\n{text}",
                    outline.len(),
                    distance_to_outline(&outline, p)
                );
                checked += 1;
                hits += usize::from(expected);
            }
        }
    }
    assert!(
        checked > 40_000 && hits > 10_000,
        "{checked} rays, {hits} hits"
    );
}

#[test]
fn the_reported_star_patch_is_not_hit_outside_its_outline() {
    let text = include_str!("nff/concave_patch.nff");
    let mut scene = parse_nff(text, Path::new("concave_patch.nff")).unwrap();
    let as_polygon = text.replace("pp 12", "p 12");
    let as_polygon: String = as_polygon
        .lines()
        .map(|line| {
            let words: Vec<&str> = line.split_whitespace().collect();
            if words.len() == 6 && words.iter().all(|w| w.parse::<f64>().is_ok()) {
                words[..3].join(" ")
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let polygon = parse_nff(&as_polygon, Path::new("concave_polygon.nff")).unwrap();
    // The pixel the report names: at 96x96, column 9, row 38.
    scene.settings.width = 96;
    scene.settings.height = 96;
    let ray = scene.camera.ray(96, 96, 9.5, 38.5);
    assert!(World::new(&scene.objects).intersect(&ray).is_none());
    assert!(World::new(&polygon.objects).intersect(&ray).is_none());
    // The same pixels are covered either way.
    let covered = |objects| {
        let world = World::new(objects);
        (0..96 * 96)
            .filter(|i| {
                let (x, y) = (f64::from(i % 96) + 0.5, f64::from(i / 96) + 0.5);
                world.intersect(&scene.camera.ray(96, 96, x, y)).is_some()
            })
            .count()
    };
    assert_eq!(covered(&scene.objects), 83);
    assert_eq!(covered(&polygon.objects), 83);
}
