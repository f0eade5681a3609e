use std::path::Path;

use super::*;
use crate::math::Vec3;

fn parse(source: &str) -> LoadedScene {
    parse_obj(source, Path::new("model.obj")).unwrap()
}

#[test]
fn vertices_are_shared_and_one_mesh_is_made_per_material() {
    let loaded = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
    let scene = loaded.scene;
    assert_eq!(scene.objects.meshes.len(), 1);
    assert_eq!(scene.objects.meshes[0].positions().len(), 4);
    assert_eq!(scene.objects.meshes[0].len(), 2);
    assert_eq!(scene.materials, vec![Material::default()]);
    assert!(loaded.warnings.is_empty());
}

#[test]
fn a_bare_model_is_framed_and_lit_from_the_eye() {
    let scene = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").scene;
    assert_eq!((scene.settings.width, scene.settings.height), (640, 480));
    assert_eq!(scene.camera.fov_degrees(), DEFAULT_FOV_DEGREES);
    assert_eq!(scene.lights, vec![headlight(&scene.camera)]);
    assert_eq!(scene.ambient, Color::splat(AMBIENT));
}

#[test]
fn unknown_statements_and_lines_are_warned_about_once() {
    let loaded = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\ncstype bezier\nf 1 2 3\n");
    let text: Vec<String> = loaded.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(text.len(), 2, "{text:?}");
    assert!(text[0].starts_with("model.obj:4:1: warning: points and lines (`l`) are not rendered"));
    assert!(text[1].starts_with("model.obj:6:1: warning: unknown statement `cstype`"));
}

#[test]
fn a_file_without_s_is_smoothed_and_given_normals_are_kept() {
    let roof = "v -1 0 0\nv 0 1 0\nv 1 0 0\nv -1 0 1\nv 0 1 1\nv 1 0 1\nf 1 4 5 2\nf 2 5 6 3\n";
    let scene = parse(roof).scene;
    assert_eq!(scene.objects.meshes[0].positions().len(), 6);
    let normals = parse(&format!("{roof}vn 0 0 1\nf 1//1 2//1 3//1\n")).scene;
    assert_eq!(normals.objects.meshes[0].positions().len(), 9);
    let ridge = Vec3::new(0.0, 1.0, 0.5);
    let ray = crate::math::Ray::new(Vec3::new(0.0, 5.0, 0.5), -Vec3::Y);
    let mesh = &scene.objects.meshes[0];
    let shear = crate::shape::RayShear::new(&ray);
    let (i, hit) = (0..mesh.len() as u32)
        .find_map(|i| mesh.intersect(i, &ray, &shear).map(|h| (i, h)))
        .unwrap();
    let surface = mesh.surface(i, &ray, &hit);
    assert!((surface.local.point - ridge).length() < 1e-9);
    assert!((surface.shading_normal - Vec3::Y).length() < 1e-9);
}

#[test]
fn a_face_that_crosses_itself_covers_its_wings_with_attributes_interpolated_along_its_edges() {
    // A bow tie of two wings meeting at (1.2, 1.2), texture coordinates
    // a third of the position: a vertex made on an edge, where the face
    // crosses itself, must carry the edge's blend, which is that too.
    let scene = parse(
        "v 0 0 0\nv 3 3 0\nv 3 0 0\nv 0 2 0\n\
         vt 0 0\nvt 1 1\nvt 1 0\nvt 0 0.6666666666666666\n\
         f 1/1 2/2 3/3 4/4\n",
    )
    .scene;
    assert!(scene.objects.meshes[0].positions().len() > 4);
    let world = crate::world::World::new(&scene.objects);
    let down = |x: f64, y: f64| crate::math::Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
    let mut hits = 0;
    for i in 0..30 {
        for j in 0..30 {
            let (x, y) = (0.05 + 0.1 * f64::from(i), 0.05 + 0.1 * f64::from(j));
            let ray = down(x, y);
            // Inside the left wing (below y = 2 - 2x/3, above y = x) or the
            // right one (between the same lines the other way round).
            let (a, b) = (y - x, y - (2.0 - 2.0 * x / 3.0));
            if a.abs() < 1e-9 || b.abs() < 1e-9 {
                continue;
            }
            let inside = a * b < 0.0 && x < 3.0;
            match world.intersect(&ray) {
                Some(hit) => {
                    assert!(inside, "({x}, {y}) is outside the bow tie");
                    let uv = world.surface(&ray, &hit).uv;
                    assert!((uv.x - x / 3.0).abs() < 1e-9 && (uv.y - y / 3.0).abs() < 1e-9);
                    hits += 1;
                }
                None => assert!(!inside, "({x}, {y}) is inside the bow tie"),
            }
        }
    }
    assert!(hits > 300, "{hits}");
}

#[test]
fn normals_and_texture_coordinates_that_do_not_exist_are_dropped_with_one_warning() {
    // The `vn` and `vt` lines commented out, as exporters' users do.
    let roof = "v -1 0 0\nv 0 1 0\nv 1 0 0\nv -1 0 1\nv 0 1 1\nv 1 0 1\n";
    let without = parse(&format!("{roof}f 1 4 5 2\nf 2 5 6 3\n")).scene;
    let loaded = parse(&format!(
        "{roof}# vn 0 1 0\n# vt 0 0\nf 1//1 4//1 5//1 2//1\nf 2/1/2 5/1/2 6/1/2 3/1/2\n"
    ));
    let text: Vec<String> = loaded.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(text.len(), 2, "{text:?}");
    assert!(
        text[0].starts_with(
            "model.obj:9:6: warning: normal index 1 is out of range: 0 normals are defined \
             before this line; faces that refer to normals that do not exist get normals \
             computed as for a face without any (warned once per file)\n"
        ),
        "{}",
        text[0]
    );
    assert!(
        text[1].starts_with(
            "model.obj:10:5: warning: texture coordinate index 1 is out of range: \
             0 texture coordinates are defined before this line; faces that refer to \
             texture coordinates that do not exist are read without texture coordinates"
        ),
        "{}",
        text[1]
    );
    // The same mesh as without the indices: computed normals, no (u, v).
    assert_eq!(loaded.scene.objects.meshes, without.objects.meshes);
}

#[test]
fn every_library_of_an_mtllib_line_is_read_and_a_missing_one_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    std::fs::write(dir.path().join("my b.mtl"), "newmtl blue\nKd 0 0 1\n").unwrap();
    let source = "mtllib a.mtl gone.mtl my\\ b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
                  usemtl red\nf 1 2 3\nusemtl blue\nf 1 3 2\n";
    let loaded = parse_obj(source, &dir.path().join("m.obj")).unwrap();
    let text: Vec<String> = loaded.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(text.len(), 1, "{text:?}");
    assert!(
        text[0].contains("m.obj:1:14: warning: cannot read the material library `")
            && text[0].contains("gone.mtl` ("),
        "{}",
        text[0]
    );
    let diffuse: Vec<&crate::shading::Texture> =
        loaded.scene.materials.iter().map(|m| &m.diffuse).collect();
    assert_eq!(
        diffuse,
        [
            &Color::new(1.0, 0.0, 0.0).into(),
            &Color::new(0.0, 0.0, 1.0).into()
        ]
    );
}
