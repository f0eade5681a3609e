//! `whitted explain --svg`: the rendered picture (embedded as a base64
//! PNG) with the ray tree projected over it through the scene's camera.
//! Rays are coloured by kind, shadow rays dashed (yellow where they reach
//! the light, red where blocked), hit points marked; hovering over a mark
//! or a ray shows what it is.

use std::fmt::Write;
use std::path::Path;

use whitted::integrator::{LightVerdict, RayKind, RayNode};
use whitted::math::{DVec2, Vec3};
use whitted::render::{PixelExplanation, Scene};

use crate::explain_text::{kind_name, object_label};

/// The stroke colour of each kind of ray.
fn stroke(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Primary => "#ffffff",
        RayKind::Reflected => "#33d6ff",
        RayKind::Refracted => "#ff4dd2",
        RayKind::Shadow => "#ffd633",
    }
}

/// Colour of a blocked shadow ray.
const BLOCKED: &str = "#ff3333";

/// The drawing: `png` (the rendered picture) under the tree of
/// `explanation`.
pub fn svg_drawing(
    scene: &Scene,
    file: Option<&Path>,
    explanation: &PixelExplanation,
    png: &[u8],
) -> String {
    let (width, height) = (scene.settings.width, scene.settings.height);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\">"
    );
    let _ = writeln!(
        svg,
        "<title>ray tree of pixel {},{}, sample {}</title>",
        explanation.x, explanation.y, explanation.sample
    );
    let _ = writeln!(
        svg,
        "<image width=\"{width}\" height=\"{height}\" href=\"data:image/png;base64,{}\"/>",
        base64(png)
    );
    let mut drawing = Drawing {
        scene,
        file,
        svg,
        far: 1e3
            * (scene.camera.eye() - scene.camera.look_at())
                .length()
                .max(1.0),
        line: (f64::from(width.max(height)) / 400.0).max(1.0),
    };
    drawing.node(&explanation.tree);
    let cut = (explanation.left_out > 0).then(|| {
        format!(
            "tree cut at {} rays: {} more not drawn",
            explanation.max_tree_rays, explanation.left_out
        )
    });
    drawing.legend(cut.as_deref());
    drawing.svg.push_str("</svg>\n");
    drawing.svg
}

/// An SVG being drawn.
struct Drawing<'s> {
    scene: &'s Scene,
    /// The scene file, to say where objects are defined.
    file: Option<&'s Path>,
    svg: String,
    /// How far a ray that leaves the scene is drawn.
    far: f64,
    /// Line width, in pixels.
    line: f64,
}

impl Drawing<'_> {
    fn project(&self, point: Vec3) -> (DVec2, f64) {
        let s = &self.scene.settings;
        self.scene.camera.project(s.width, s.height, point)
    }

    /// The segment `a`–`b` on the image, cut where it passes behind the
    /// eye and to a margin around the image; `None` when none of it is
    /// left.
    fn segment(&self, a: Vec3, b: Vec3) -> Option<(DVec2, DVec2)> {
        let near = 1e-6 * self.far;
        let (da, db) = (self.project(a).1, self.project(b).1);
        if da <= near && db <= near {
            return None;
        }
        let cut = |from: Vec3, d_from: f64, to: Vec3, d_to: f64| {
            if d_from > near {
                from
            } else {
                from + (to - from) * ((near - d_from) / (d_to - d_from))
            }
        };
        let (a, b) = (cut(a, da, b, db), cut(b, db, a, da));
        let s = &self.scene.settings;
        let size = DVec2::new(f64::from(s.width), f64::from(s.height));
        clip(self.project(a).0, self.project(b).0, -size, 2.0 * size)
    }

    fn line(&mut self, a: Vec3, b: Vec3, color: &str, dashed: bool, title: &str) {
        let Some((p, q)) = self.segment(a, b) else {
            return;
        };
        let dash = if dashed {
            format!(" stroke-dasharray=\"{0} {0}\"", 3.0 * self.line)
        } else {
            String::new()
        };
        let _ = writeln!(
            self.svg,
            "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{color}\" \
             stroke-width=\"{:.2}\"{dash}><title>{}</title></line>",
            p.x,
            p.y,
            q.x,
            q.y,
            self.line,
            escape(title)
        );
    }

    fn mark(&mut self, at: Vec3, color: &str, title: &str) {
        let (p, depth) = self.project(at);
        if depth <= 0.0 {
            return;
        }
        let _ = writeln!(
            self.svg,
            "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"{:.2}\" fill=\"{color}\" stroke=\"#000000\" \
             stroke-width=\"{:.2}\"><title>{}</title></circle>",
            p.x,
            p.y,
            2.5 * self.line,
            self.line / 2.0,
            escape(title)
        );
    }

    /// A ray, its shadow rays and, recursively, its children.
    fn node(&mut self, node: &RayNode) {
        let kind = kind_name(node.kind);
        let end = match &node.hit {
            Some(hit) => hit.point,
            None => node.origin + node.direction * self.far,
        };
        let title = format!("{kind} ray, depth {}", node.depth);
        self.line(node.origin, end, stroke(node.kind), false, &title);
        let Some(hit) = &node.hit else {
            return;
        };
        for light in &hit.lights {
            let blocked = matches!(light.verdict, LightVerdict::Blocked { .. });
            let color = if blocked {
                BLOCKED
            } else {
                stroke(RayKind::Shadow)
            };
            for segment in &light.shadow_rays {
                let length = segment
                    .blocker
                    .map_or(segment.t_max, |(_, t)| t)
                    .min(self.far);
                let to = segment.origin + segment.direction * length;
                let title = format!("shadow ray towards light {}", light.index);
                self.line(segment.origin, to, color, true, &title);
            }
        }
        for child in &hit.children {
            self.node(child);
        }
        let title = format!(
            "{kind} ray hits {} at t = {:.4}",
            object_label(self.scene, self.file, hit.primitive),
            hit.t
        );
        self.mark(hit.point, stroke(node.kind), &title);
    }

    /// The colours' key, and `note` (in white) under it when given.
    fn legend(&mut self, note: Option<&str>) {
        let size = 10.0 * self.line;
        let entries = [
            ("camera", stroke(RayKind::Primary)),
            ("reflected", stroke(RayKind::Reflected)),
            ("refracted", stroke(RayKind::Refracted)),
            ("shadow, lit", stroke(RayKind::Shadow)),
            ("shadow, blocked", BLOCKED),
        ];
        let note = note.map(|text| (text, "#ffffff"));
        for (i, (name, color)) in entries.into_iter().chain(note).enumerate() {
            let y = size * (1.5 + 1.2 * i as f64);
            let _ = writeln!(
                self.svg,
                "<text x=\"{:.1}\" y=\"{y:.1}\" font-family=\"sans-serif\" font-size=\"{size:.1}\" \
                 fill=\"{color}\" stroke=\"#000000\" stroke-width=\"{:.2}\" \
                 paint-order=\"stroke\">{name}</text>",
                size / 2.0,
                self.line / 2.0
            );
        }
    }
}

/// The part of segment `p`–`q` inside the box from `min` to `max`
/// (Liang and Barsky's clipping).
fn clip(p: DVec2, q: DVec2, min: DVec2, max: DVec2) -> Option<(DVec2, DVec2)> {
    let d = q - p;
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (denominator, numerator) in [
        (-d.x, p.x - min.x),
        (d.x, max.x - p.x),
        (-d.y, p.y - min.y),
        (d.y, max.y - p.y),
    ] {
        if denominator == 0.0 {
            if numerator < 0.0 {
                return None;
            }
        } else {
            let t = numerator / denominator;
            if denominator < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1).then(|| (p + d * t0, p + d * t1))
}

/// Text safe inside an SVG element.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Standard base64 (RFC 4648, with padding).
pub(crate) fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_examples() {
        for (plain, encoded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), encoded);
        }
    }

    #[test]
    fn segments_are_clipped_to_the_box() {
        let (min, max) = (DVec2::ZERO, DVec2::new(10.0, 10.0));
        let inside = (DVec2::new(1.0, 1.0), DVec2::new(9.0, 2.0));
        assert_eq!(clip(inside.0, inside.1, min, max), Some(inside));
        let across = clip(DVec2::new(-10.0, 5.0), DVec2::new(20.0, 5.0), min, max);
        assert_eq!(across, Some((DVec2::new(0.0, 5.0), DVec2::new(10.0, 5.0))));
        assert_eq!(
            clip(DVec2::new(-1.0, -1.0), DVec2::new(-5.0, 20.0), min, max),
            None
        );
    }

    #[test]
    fn titles_are_escaped() {
        assert_eq!(escape("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    }
}
