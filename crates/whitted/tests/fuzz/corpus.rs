//! The inputs mutations start from: every fixture of the format in the
//! repository, plus inputs generated here (each kind of entity with random
//! numbers, deep nesting, images of every PNG colour type and bit depth,
//! headers claiming huge sizes).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use whitted::math::random::Rng;

/// The repository's root.
pub fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The files under `folder` (relative to the repository, searched
/// recursively) whose names end in one of `extensions`, sorted.
pub fn fixtures(folder: &str, extensions: &[&str]) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![repository().join(folder)];
    while let Some(dir) = pending.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                pending.push(path);
            } else if path
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
            {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// The contents of the files, skipping any over the input cap.
pub fn read_all(paths: &[PathBuf]) -> Vec<Vec<u8>> {
    paths
        .iter()
        .filter_map(|p| std::fs::read(p).ok())
        .filter(|bytes| bytes.len() <= super::mutate::MAX_INPUT)
        .collect()
}

/// The distinct words of `inputs` plus `extra`: what token mutations
/// insert.
pub fn vocabulary(inputs: &[Vec<u8>], extra: &[&str]) -> Vec<String> {
    let mut words: Vec<String> = inputs
        .iter()
        .flat_map(|input| {
            String::from_utf8_lossy(input)
                .split_whitespace()
                .filter(|w| w.len() <= 40)
                .map(str::to_string)
                .collect::<Vec<_>>()
        })
        .chain(extra.iter().map(|w| w.to_string()))
        .collect();
    words.sort();
    words.dedup();
    words
}

/// A "nice" random number: small, sometimes whole, sometimes negative.
fn number(rng: &mut Rng) -> String {
    match rng.below(4) {
        0 => format!("{}", rng.below(5)),
        1 => format!("{:.3}", rng.range(-3.0, 3.0)),
        2 => format!("{:.2}", rng.range(0.0, 1.0)),
        _ => format!("{}", rng.below(200) as i32 - 100),
    }
}

/// A positive number, at most 3.
fn positive(rng: &mut Rng) -> String {
    format!("{:.3}", rng.range(0.05, 3.0))
}

/// A weight in [0, 1].
fn weight(rng: &mut Rng) -> String {
    format!("{:.2}", rng.range(0.0, 1.0))
}

/// `n` results of `f` separated by `separator`.
fn several(rng: &mut Rng, n: usize, separator: &str, f: fn(&mut Rng) -> String) -> String {
    (0..n).map(|_| f(rng)).collect::<Vec<_>>().join(separator)
}

/// `n` numbers separated by `separator`.
fn numbers(rng: &mut Rng, n: usize, separator: &str) -> String {
    (0..n)
        .map(|_| number(rng))
        .collect::<Vec<_>>()
        .join(separator)
}

/// A TOML vector `[x, y, z]` of nice numbers.
fn toml_vec3(rng: &mut Rng) -> String {
    format!("[{}]", numbers(rng, 3, ", "))
}

/// A TOML scene with every kind of shape, light, texture and transform
/// step, its numbers random but mostly valid, so that mutations of it reach
/// the renderer.
pub fn toml_scene(rng: &mut Rng) -> String {
    let mut s = String::new();
    let v = |rng: &mut Rng| toml_vec3(rng);
    let p = |rng: &mut Rng| positive(rng);
    let w = |rng: &mut Rng| weight(rng);
    let color = |rng: &mut Rng| format!("[{}]", several(rng, 3, ", ", weight));
    let _ = writeln!(
        s,
        "[render]\nwidth = 8\nheight = 6\nsamples = {}\nmax_depth = {}\nmin_weight = {}\n\
         background = {}\nambient = {}\naccel = \"{}\"",
        1 + rng.below(3),
        rng.below(6),
        w(rng),
        color(rng),
        w(rng),
        ["bvh", "kdtree", "grid", "linear"][rng.below(4) as usize],
    );
    let _ = writeln!(
        s,
        "[camera]\neye = [{}, {}, 8]\nlook_at = {}\nup = [0, 1, 0]\nfov = {}",
        number(rng),
        number(rng),
        v(rng),
        rng.below(100) + 10
    );
    let _ = writeln!(
        s,
        "[materials.a]\ndiffuse = {{ checker = {{ even = {}, odd = {}, size = {} }} }}\n\
         specular = {}\nshininess = {}\nreflection = {}\ntransmission = {}\nior = {}\n\
         fresnel = true\nemission = {}\nambient = {}",
        w(rng),
        color(rng),
        p(rng),
        w(rng),
        p(rng),
        w(rng),
        w(rng),
        p(rng),
        w(rng),
        w(rng)
    );
    let _ = writeln!(
        s,
        "[materials.b]\ndiffuse = {{ image = \"textures/bricks.png\", wrap = \"{}\", \
         scale = [{}, {}], offset = [{}, {}] }}",
        ["repeat", "clamp", "mirror"][rng.below(3) as usize],
        p(rng),
        p(rng),
        number(rng),
        number(rng)
    );
    let _ = writeln!(
        s,
        "[[lights]]\ntype = \"point\"\nposition = {}\nintensity = {}\nattenuation = [1, {}, {}]\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0, -1, {}]\nintensity = {}",
        v(rng),
        w(rng),
        w(rng),
        w(rng),
        number(rng),
        w(rng)
    );
    let shapes = [
        format!(
            "shape = \"sphere\"\ncenter = {}\nradius = {}",
            v(rng),
            p(rng)
        ),
        format!(
            "shape = \"plane\"\npoint = {}\nnormal = [0, 1, {}]",
            v(rng),
            number(rng)
        ),
        format!(
            "shape = \"triangle\"\nvertices = [{}, {}, {}]",
            v(rng),
            v(rng),
            v(rng)
        ),
        format!(
            "shape = \"polygon\"\nvertices = [[0, 0, 0], [{p}, 0, 0], [{p}, {q}, 0], [{r}, {q}, 0]]",
            p = p(rng),
            q = p(rng),
            r = number(rng)
        ),
        format!(
            "shape = \"parallelogram\"\norigin = {}\nedge_u = {}\nedge_v = {}",
            v(rng),
            v(rng),
            v(rng)
        ),
        format!(
            "shape = \"disk\"\ncenter = {}\nnormal = {}\nradius = 3\ninner_radius = {}",
            v(rng),
            v(rng),
            w(rng)
        ),
        format!(
            "shape = \"cylinder\"\nbase = {}\ntop = {}\nradius = {}\ncaps = {}",
            v(rng),
            v(rng),
            p(rng),
            rng.below(2) == 0
        ),
        format!(
            "shape = \"cone\"\nbase = {}\nbase_radius = {}\ntop = {}\ntop_radius = {}\ncaps = {}",
            v(rng),
            p(rng),
            v(rng),
            w(rng),
            rng.below(2) == 0
        ),
        format!(
            "shape = \"box\"\nmin = [-1, -1, -1]\nmax = [{}]",
            several(rng, 3, ", ", positive)
        ),
        format!(
            "shape = \"quadric\"\na = {}\nc = {}\nd = {}\ne = {}\nh = -1\nj = {}\n\
             bounds = [[-1, -1, -1], [{}]]",
            p(rng),
            p(rng),
            w(rng),
            number(rng),
            number(rng),
            several(rng, 3, ", ", positive)
        ),
        format!(
            "shape = \"torus\"\nmajor = {}\nminor = {}",
            number(rng),
            p(rng)
        ),
        format!(
            "shape = \"implicit\"\nfunction = \"{}\"\n\
             bounds = [[-1, -1, -1], [{}]]\nmax_gradient = {}",
            [
                format!("x^2 + y^2 + z^2 - {}", p(rng)),
                format!("sin({}*x)*cos(y) + z - {}", p(rng), number(rng)),
                format!("max(abs(x), abs(y)) + z^3 - {}", w(rng)),
            ][rng.below(3) as usize],
            several(rng, 3, ", ", positive),
            p(rng)
        ),
        format!(
            "shape = \"bezier_patch\"\npoints = [{}]",
            (0..4)
                .map(|i| format!(
                    "[{}]",
                    (0..4)
                        .map(|j| format!("[{i}, {j}, {}]", number(rng)))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        format!(
            "shape = \"superellipsoid\"\ne = {}\nn = {}\ncenter = {}\nradius = {}",
            p(rng),
            p(rng),
            v(rng),
            p(rng)
        ),
    ];
    for shape in shapes {
        let material = ["a", "b"][rng.below(2) as usize];
        let step = match rng.below(5) {
            0 => format!("{{ translate = {} }}", v(rng)),
            1 => format!("{{ scale = [{}] }}", several(rng, 3, ", ", positive)),
            2 => format!("{{ scale = {} }}", p(rng)),
            3 => format!(
                "{{ rotate = {{ axis = [1, {}, 0], angle = {} }} }}",
                number(rng),
                number(rng)
            ),
            _ => format!(
                "{{ matrix = [[1, {}, 0, {}], [0, 1, {}, {}], [0, 0, 1, {}]] }}",
                w(rng),
                number(rng),
                w(rng),
                number(rng),
                number(rng)
            ),
        };
        let _ = writeln!(
            s,
            "[[objects]]\n{shape}\nmaterial = \"{material}\"\ntransform = [{step}]"
        );
    }
    s
}

/// TOML nested `depth` deep, in arrays or inline tables: a parser that
/// recurses must not overflow its stack.
pub fn deep_toml(depth: usize, tables: bool) -> String {
    let (open, close) = if tables { ("{a=", "}") } else { ("[", "]") };
    format!(
        "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = {}1{}\n",
        open.repeat(depth),
        close.repeat(depth)
    )
}

/// An NFF scene with every kind of entity, its numbers random but mostly
/// valid, so that mutations of it reach the renderer.
pub fn nff_scene(rng: &mut Rng) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "v\nfrom {} {} 8\nat {}\nup 0 1 0\nangle {}\nhither {}\nresolution {} {}",
        number(rng),
        number(rng),
        numbers(rng, 3, " "),
        10 + rng.below(100),
        weight(rng),
        1 + rng.below(9),
        1 + rng.below(9)
    );
    let _ = writeln!(s, "b {}", several(rng, 3, " ", weight));
    let _ = writeln!(s, "l {}", numbers(rng, 3, " "));
    let _ = writeln!(
        s,
        "l {} {}",
        numbers(rng, 3, " "),
        several(rng, 3, " ", weight)
    );
    for _ in 0..1 + rng.below(3) {
        let _ = writeln!(s, "f {} {}", several(rng, 7, " ", weight), positive(rng));
        let _ = writeln!(s, "s {} {}", numbers(rng, 3, " "), positive(rng));
        let _ = writeln!(
            s,
            "c\n{} {}\n{} {}",
            numbers(rng, 3, " "),
            positive(rng),
            numbers(rng, 3, " "),
            weight(rng)
        );
        let vertices = 3 + rng.below(4) as usize;
        // Polygons lie in a plane z = constant: others are refused.
        let z = number(rng);
        let _ = writeln!(s, "p {vertices}");
        for _ in 0..vertices {
            let _ = writeln!(s, "{} {z}", numbers(rng, 2, " "));
        }
        let _ = writeln!(s, "pp {vertices}");
        for _ in 0..vertices {
            let normal = several(rng, 3, " ", positive);
            let _ = writeln!(s, "{} {z} {normal}", numbers(rng, 2, " "));
        }
    }
    s
}

/// An OBJ model with positions, texture coordinates, normals, smoothing
/// groups, materials and faces of every form, indices random (sometimes
/// negative).
pub fn obj_model(rng: &mut Rng) -> String {
    let mut s = String::from("mtllib fuzz.mtl\no model\n");
    let vertices = 3 + rng.below(8) as i64;
    for _ in 0..vertices {
        let _ = writeln!(s, "v {}", numbers(rng, 3, " "));
        let _ = writeln!(s, "vt {}", numbers(rng, 2, " "));
        let _ = writeln!(s, "vn {}", numbers(rng, 3, " "));
    }
    for _ in 0..1 + rng.below(6) {
        match rng.below(4) {
            0 => s.push_str("usemtl fuzz\n"),
            1 => s.push_str("s 1\n"),
            2 => s.push_str("s off\n"),
            _ => s.push_str("g part\n"),
        }
        let corners = 3 + rng.below(4);
        let form = rng.below(4);
        s.push('f');
        for _ in 0..corners {
            let mut index = || {
                let i = 1 + i64::from(rng.below(vertices as u32));
                if rng.below(3) == 0 {
                    i - vertices - 1
                } else {
                    i
                }
            };
            let _ = match form {
                0 => write!(s, " {}", index()),
                1 => write!(s, " {}/{}", index(), index()),
                2 => write!(s, " {}//{}", index(), index()),
                _ => write!(s, " {}/{}/{}", index(), index(), index()),
            };
        }
        s.push('\n');
    }
    s
}

/// An MTL library of one material `fuzz` with every statement we read.
pub fn mtl_library(rng: &mut Rng) -> String {
    format!(
        "newmtl fuzz\nKa {}\nKd {}\nKs {}\nKe {}\nTf {}\nNs {}\nNi {}\nd {}\nTr {}\nillum {}\n\
         map_Kd -s {} -o {} -clamp on textures/quadrants.png\nmap_Ks textures/quadrants.png\n\
         map_Ka textures/quadrants.png\nbump -bm {} textures/quadrants.png\n\
         norm textures/quadrants.png\nmap_d textures/quadrants.png\n",
        several(rng, 3, " ", weight),
        several(rng, 3, " ", weight),
        several(rng, 3, " ", weight),
        several(rng, 3, " ", weight),
        several(rng, 3, " ", weight),
        positive(rng),
        positive(rng),
        weight(rng),
        weight(rng),
        rng.below(11),
        several(rng, 2, " ", positive),
        numbers(rng, 2, " "),
        weight(rng),
    )
}

/// A PNG of random size (1 to 9 pixels a side), colour type and bit depth.
pub fn png_image(rng: &mut Rng) -> Vec<u8> {
    use png::{BitDepth, ColorType};
    let (color, channels) = [
        (ColorType::Grayscale, 1),
        (ColorType::GrayscaleAlpha, 2),
        (ColorType::Rgb, 3),
        (ColorType::Rgba, 4),
        (ColorType::Indexed, 1),
    ][rng.below(5) as usize];
    let depth = match color {
        ColorType::Indexed | ColorType::Grayscale if rng.below(2) == 0 => BitDepth::Four,
        ColorType::Indexed => BitDepth::Eight,
        _ if rng.below(2) == 0 => BitDepth::Sixteen,
        _ => BitDepth::Eight,
    };
    let (width, height) = (1 + rng.below(9), 1 + rng.below(9));
    let bits = channels * depth as usize;
    let row = (width as usize * bits).div_ceil(8);
    let data: Vec<u8> = (0..row * height as usize)
        .map(|_| rng.next_u32() as u8)
        .collect();
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(color);
    encoder.set_depth(depth);
    if color == ColorType::Indexed {
        encoder.set_palette((0..48).map(|_| rng.next_u32() as u8).collect::<Vec<_>>());
    }
    let written = encoder
        .write_header()
        .and_then(|mut writer| writer.write_image_data(&data));
    assert!(written.is_ok(), "the png encoder refused {width}x{height}");
    bytes
}

/// A PNG whose header claims `width`×`height` RGB pixels, followed by
/// the header's own CRC and nothing else.
pub fn png_header(width: u32, height: u32) -> Vec<u8> {
    let mut chunk = b"IHDR".to_vec();
    chunk.extend_from_slice(&width.to_be_bytes());
    chunk.extend_from_slice(&height.to_be_bytes());
    chunk.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut bytes = b"\x89PNG\r\n\x1a\n".to_vec();
    bytes.extend_from_slice(&13u32.to_be_bytes());
    bytes.extend_from_slice(&chunk);
    bytes.extend_from_slice(&crc32(&chunk).to_be_bytes());
    bytes
}

/// The repository's JPEG fixture with its size fields set to `width` and
/// `height`, its data left as it is (too short for a large size).
pub fn jpeg_claiming(width: u16, height: u16) -> Vec<u8> {
    let mut bytes = include_bytes!("../textures/two_blocks.jpg").to_vec();
    if let Some(sof) = bytes
        .windows(2)
        .position(|w| w == [0xff, 0xc0] || w == [0xff, 0xc2])
    {
        // Marker, length, precision, then height and width.
        bytes[sof + 5..sof + 7].copy_from_slice(&height.to_be_bytes());
        bytes[sof + 7..sof + 9].copy_from_slice(&width.to_be_bytes());
    }
    bytes
}

/// The CRC-32 of PNG chunks (ISO 3309), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = u32::MAX;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// `count` ray records of the Embree harness format: pixel, origin,
/// direction, t_far, with nice random numbers.
pub fn ray_records(rng: &mut Rng, count: usize) -> Vec<u8> {
    let mut bytes = Vec::new();
    for pixel in 0..count as u32 {
        bytes.extend_from_slice(&pixel.to_le_bytes());
        for _ in 0..7 {
            bytes.extend_from_slice(&(rng.range(-3.0, 3.0) as f32).to_le_bytes());
        }
    }
    bytes
}

#[test]
fn png_headers_carry_a_valid_crc() {
    // The CRC of "IEND", as every PNG ends with it.
    assert_eq!(crc32(b"IEND"), 0xae42_6082);
}

/// How many of 100 generated inputs `parse` accepts, with the first
/// refusal.
fn accepted(
    generate: fn(&mut Rng) -> String,
    parse: impl Fn(&str) -> Result<(), String>,
) -> (usize, String) {
    let mut rng = Rng::new(11);
    let mut first = String::new();
    let count = (0..100)
        .filter(|_| match parse(&generate(&mut rng)) {
            Ok(()) => true,
            Err(e) => {
                if first.is_empty() {
                    first = e;
                }
                false
            }
        })
        .count();
    (count, first)
}

#[test]
fn generated_scenes_mostly_parse() {
    let folder = repository().join("scenes");
    let (toml, why) = accepted(toml_scene, |text| {
        whitted::scene::parse_scene(text, &folder.join("fuzz.toml"))
            .map(drop)
            .map_err(|e| e.to_string())
    });
    assert!(
        toml >= 80,
        "{toml} of 100 TOML scenes parse; first refusal:\n{why}"
    );
    let (nff, why) = accepted(nff_scene, |text| {
        whitted::scene::parse_nff(text, Path::new("fuzz.nff"))
            .map(drop)
            .map_err(|e| e.to_string())
    });
    assert!(
        nff >= 80,
        "{nff} of 100 NFF scenes parse; first refusal:\n{why}"
    );
}
