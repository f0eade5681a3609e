//! `whitted explain`'s text: the ray tree, one ray after the other, each
//! indented under the ray it came from (`docs/explain.md` shows how to
//! read it).

use std::fmt::Write;
use std::path::Path;

use whitted::accel::TraversalCounters;
use whitted::integrator::{HitNode, LightVerdict, RayKind, RayNode, Stop};
use whitted::math::Vec3;
use whitted::render::{AntiAliasing, PixelExplanation, Scene};
use whitted::shading::Color;
use whitted::world::PrimitiveId;

/// The name of a ray's kind in explanations (`camera` for the primary ray).
pub fn kind_name(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Primary => "camera",
        other => other.name(),
    }
}

/// A colour with four decimals.
fn color(c: Color) -> String {
    format!("({:.4}, {:.4}, {:.4})", c.r, c.g, c.b)
}

/// A point or direction with four decimals.
fn vector(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

fn cost(c: TraversalCounters) -> String {
    format!(
        "{} nodes visited, {} primitives tested",
        c.nodes, c.primitives
    )
}

/// How people are told which object a primitive is: its name or index in
/// the scene file, its kind, its number, and where the file defines it.
pub fn object_label(scene: &Scene, file: Option<&Path>, id: PrimitiveId) -> String {
    let Some(description) = scene.describe_primitive(id) else {
        return format!("primitive {}", id.0);
    };
    let mut label = match &description.source {
        Some(source) => format!("{} {}", source.label, description.kind),
        None => description.kind.to_string(),
    };
    if let Some((_, triangle)) = description.triangle_of {
        let _ = write!(label, " (triangle {triangle} of its mesh)");
    }
    let _ = write!(label, ", primitive {}", id.0);
    let location = description.source.and_then(|s| s.location);
    if let Some(location) = location {
        let file = file.map_or("built-in scene".into(), |f| f.display().to_string());
        let _ = write!(label, ", {file}:{}:{}", location.line, location.column);
    }
    label
}

/// The whole explanation as text.
pub fn explanation_text(scene: &Scene, file: Option<&Path>, e: &PixelExplanation) -> String {
    let mut out = String::new();
    let name = file.map_or("the built-in scene".into(), |f| f.display().to_string());
    let settings = &scene.settings;
    let _ = writeln!(
        out,
        "pixel {},{} of {name} ({}x{}), sample {} of {} at ({:.4}, {:.4})",
        e.x, e.y, settings.width, settings.height, e.sample, e.samples, e.position.x, e.position.y
    );
    let _ = writeln!(
        out,
        "structure {}, max_depth {}, min_weight {}, at most {} secondary rays",
        e.accel.name(),
        e.limits.max_depth,
        e.limits.min_weight,
        e.limits.ray_budget
    );
    if e.left_out > 0 {
        let _ = writeln!(
            out,
            "the tree is cut: it holds the first {} rays and light verdicts traced \
             (--max-tree-rays); {} more are in the colours but not shown, each hit says how many \
             it lost",
            e.max_tree_rays, e.left_out
        );
    }
    let [r, g, b] = e.pixel;
    let _ = writeln!(out, "pixel as rendered: ({r:.4}, {g:.4}, {b:.4})");
    match e.aa {
        AntiAliasing::Adaptive(adaptive) => {
            let _ = writeln!(
                out,
                "  {adaptive}: the area average of its squares, each the mean of its four \
                 corners; {} corners traced, on a grid 1/{} of a pixel wide (the samples, row by \
                 row); this corner's colour: {}",
                e.samples,
                1u32 << adaptive.depth,
                color(e.tree.color)
            );
        }
        AntiAliasing::Stratified if e.samples > 1 => {
            let _ = writeln!(
                out,
                "  the mean of its {} samples; this sample's colour: {}",
                e.samples,
                color(e.tree.color)
            );
        }
        AntiAliasing::Stratified => {}
    }
    out.push('\n');
    node_text(&mut out, scene, file, &e.tree, "");
    out
}

/// One ray and, indented, the rays it spawned.
fn node_text(out: &mut String, scene: &Scene, file: Option<&Path>, node: &RayNode, indent: &str) {
    let _ = writeln!(
        out,
        "{indent}{} ray, depth {}, weight {:.4}",
        kind_name(node.kind),
        node.depth,
        node.weight
    );
    let at = format!("{indent}  ");
    let _ = writeln!(
        out,
        "{at}from {} along {}",
        vector(node.origin),
        vector(node.direction)
    );
    let _ = writeln!(out, "{at}cost: {}", cost(node.cost));
    match &node.hit {
        None => {
            let _ = writeln!(out, "{at}misses everything: the background");
        }
        Some(hit) => hit_text(out, scene, file, hit, &at),
    }
    let _ = writeln!(out, "{at}passes up {}", color(node.color));
    if let Some(hit) = &node.hit {
        for child in &hit.children {
            node_text(out, scene, file, child, &format!("{indent}    "));
        }
    }
}

fn hit_text(out: &mut String, scene: &Scene, file: Option<&Path>, hit: &HitNode, at: &str) {
    let _ = writeln!(out, "{at}hits {}", object_label(scene, file, hit.primitive));
    let _ = writeln!(
        out,
        "{at}  at t = {:.6}, point {}, material {}",
        hit.t,
        vector(hit.point),
        scene.material_name(hit.material)
    );
    let side = if hit.entering {
        "arriving from outside (entering)"
    } else {
        "arriving from inside (leaving)"
    };
    let _ = writeln!(
        out,
        "{at}  shading normal {}, {side}",
        vector(hit.shading_normal)
    );
    if let Some([from, to]) = hit.indices
        && from != to
    {
        let _ = writeln!(out, "{at}  index of refraction {from} -> {to}");
    }
    let terms = &hit.terms;
    let _ = writeln!(out, "{at}terms:");
    let _ = writeln!(out, "{at}  emission ke          {}", color(terms.emission));
    let _ = writeln!(out, "{at}  ambient ka Ia        {}", color(terms.ambient));
    if hit.lights.is_empty() && !scene.lights.is_empty() {
        let _ = writeln!(
            out,
            "{at}  lights               none looked at (no diffuse or specular, or fully dissolved)"
        );
    }
    for light in &hit.lights {
        let verdict = match light.verdict {
            LightVerdict::Unreached => "does not reach this point (outside its cone)".to_string(),
            LightVerdict::FacesAway => "behind the surface: no shadow ray".to_string(),
            LightVerdict::Lit => "lit".to_string(),
            LightVerdict::Blocked { by: Some(id) } => {
                format!("blocked by {}", object_label(scene, file, id))
            }
            LightVerdict::Blocked { by: None } => "blocked".to_string(),
            LightVerdict::Attenuated { transmittance } => {
                format!(
                    "attenuated to {} by what it passes through",
                    color(transmittance)
                )
            }
        };
        let _ = writeln!(out, "{at}  light {}: {verdict}", light.index);
        if matches!(
            light.verdict,
            LightVerdict::Lit | LightVerdict::Attenuated { .. }
        ) {
            let _ = writeln!(out, "{at}    diffuse            {}", color(light.diffuse));
            let _ = writeln!(out, "{at}    specular           {}", color(light.specular));
        }
        for segment in &light.shadow_rays {
            let reach = match segment.blocker {
                None => "nothing in the way".to_string(),
                Some((id, t)) => format!("meets {} at t = {t:.6}", object_label(scene, file, id)),
            };
            let _ = writeln!(
                out,
                "{at}    shadow ray from {} along {}, length {:.4}: {reach}; cost: {}",
                vector(segment.origin),
                vector(segment.direction),
                segment.t_max,
                cost(segment.cost)
            );
        }
    }
    if terms.caustic != Color::ZERO {
        let _ = writeln!(out, "{at}  caustic kd E         {}", color(terms.caustic));
    }
    if terms.opacity != Color::ONE {
        let _ = writeln!(
            out,
            "{at}  opacity α            {} (multiplies the terms above)",
            color(terms.opacity)
        );
    }
    for child in &hit.children {
        let (name, symbol) = match child.kind {
            RayKind::Reflected => ("reflected  ", "kr"),
            _ => ("transmitted", "kt"),
        };
        let _ = writeln!(
            out,
            "{at}  {symbol} × {name}     {} × {} = {}",
            color(child.coefficient),
            color(child.color),
            color(child.coefficient * child.color)
        );
    }
    for stop in &hit.stops {
        let why = match *stop {
            Stop::DepthLimit { max_depth } => {
                format!("no secondary rays: the depth limit (max_depth {max_depth}) is reached")
            }
            Stop::Opaque => "no secondary rays: the material neither reflects nor transmits".into(),
            Stop::TotalInternalReflection => {
                "total internal reflection: no refracted ray, its weight goes to the reflected one"
                    .into()
            }
            Stop::WeightCutOff {
                kind,
                weight,
                min_weight,
            } => format!(
                "no {} ray: its weight {weight:.6} is under min_weight {min_weight}",
                kind_name(kind)
            ),
            Stop::RayBudget { kind, budget } => format!(
                "no {} ray: the sample has traced its {budget} secondary rays",
                kind_name(kind)
            ),
            Stop::TreeLimit { left_out, max_rays } => format!(
                "{left_out} more rays and light verdicts traced from here are left out of the \
                 tree (it holds {max_rays}; --max-tree-rays)"
            ),
        };
        let _ = writeln!(out, "{at}stop: {why}");
    }
}
