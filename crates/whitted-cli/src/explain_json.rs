//! `whitted explain --json`: the same tree as the text, as JSON for
//! programs and, later, the browser page of `whitted serve`. The schema is
//! `docs/explain.md`'s; `"schema": "whitted-explain/1"` names its version.
//! Numbers that are not finite (a shadow ray's length towards a
//! directional light) are `null`.

use std::path::Path;

use serde_json::{Value, json};
use whitted::accel::TraversalCounters;
use whitted::integrator::{HitNode, LightTerm, LightVerdict, RayNode, Stop};
use whitted::math::Vec3;
use whitted::render::{AntiAliasing, PixelExplanation, Scene};
use whitted::shading::Color;
use whitted::world::PrimitiveId;

use crate::explain_text::kind_name;

/// The version of the schema, to bump on an incompatible change.
pub const SCHEMA: &str = "whitted-explain/1";

fn rgb(c: Color) -> Value {
    json!([c.r, c.g, c.b])
}

fn xyz(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn cost(c: TraversalCounters) -> Value {
    json!({ "nodes": c.nodes, "primitives": c.primitives })
}

/// What a primitive is: its number, kind, and its name and place in the
/// scene file when known.
fn object(scene: &Scene, file: Option<&Path>, id: PrimitiveId) -> Value {
    let Some(description) = scene.describe_primitive(id) else {
        return json!({ "primitive": id.0 });
    };
    let source = description.source.as_ref();
    let location = source.and_then(|s| s.location);
    json!({
        "primitive": id.0,
        "kind": description.kind,
        "label": source.map(|s| s.label.clone()),
        "file": location.and(file).map(|f| f.display().to_string()),
        "line": location.map(|l| l.line),
        "column": location.map(|l| l.column),
        "mesh_instance": description.triangle_of.map(|(instance, _)| instance),
        "triangle": description.triangle_of.map(|(_, triangle)| triangle),
    })
}

/// How the pixel was sampled: the method's name, and the adaptive
/// parameters.
fn anti_aliasing(aa: AntiAliasing) -> Value {
    match aa {
        AntiAliasing::Stratified => json!({ "method": aa.name() }),
        AntiAliasing::Adaptive(a) => json!({
            "method": aa.name(),
            "threshold": a.threshold,
            "depth": a.depth,
            "min_depth": a.min_depth,
        }),
    }
}

/// The whole explanation.
pub fn explanation_json(scene: &Scene, file: Option<&Path>, e: &PixelExplanation) -> Value {
    let settings = &scene.settings;
    json!({
        "schema": SCHEMA,
        "scene": file.map(|f| f.display().to_string()),
        "image": { "width": settings.width, "height": settings.height },
        "pixel": { "x": e.x, "y": e.y, "value": e.pixel },
        "sample": {
            "index": e.sample,
            "count": e.samples,
            "position": [e.position.x, e.position.y],
            "color": rgb(e.tree.color),
        },
        "sample_colors": e.sample_colors.iter().map(|&c| rgb(c)).collect::<Vec<_>>(),
        "anti_aliasing": anti_aliasing(e.aa),
        "accel": e.accel.name(),
        "limits": {
            "max_depth": e.limits.max_depth,
            "min_weight": e.limits.min_weight,
            "ray_budget": e.limits.ray_budget,
        },
        "tree": node(scene, file, &e.tree),
    })
}

fn node(scene: &Scene, file: Option<&Path>, n: &RayNode) -> Value {
    json!({
        "kind": kind_name(n.kind),
        "depth": n.depth,
        "origin": xyz(n.origin),
        "direction": xyz(n.direction),
        "coefficient": rgb(n.coefficient),
        "weight": n.weight,
        "cost": cost(n.cost),
        "color": rgb(n.color),
        "contribution": rgb(n.coefficient * n.color),
        "hit": n.hit.as_ref().map(|hit| hit_json(scene, file, hit)),
    })
}

fn hit_json(scene: &Scene, file: Option<&Path>, hit: &HitNode) -> Value {
    json!({
        "object": object(scene, file, hit.primitive),
        "t": hit.t,
        "point": xyz(hit.point),
        "geometric_normal": xyz(hit.geometric_normal),
        "shading_normal": xyz(hit.shading_normal),
        "entering": hit.entering,
        "uv": [hit.uv.x, hit.uv.y],
        "material": { "index": hit.material.0, "name": scene.material_name(hit.material) },
        "terms": {
            "emission": rgb(hit.terms.emission),
            "ambient": rgb(hit.terms.ambient),
            "opacity": rgb(hit.terms.opacity),
        },
        "lights": hit.lights.iter().map(|l| light_json(scene, file, l)).collect::<Vec<_>>(),
        "indices_of_refraction": hit.indices,
        "children": hit.children.iter().map(|c| node(scene, file, c)).collect::<Vec<_>>(),
        "stops": hit.stops.iter().map(stop_json).collect::<Vec<_>>(),
    })
}

fn light_json(scene: &Scene, file: Option<&Path>, light: &LightTerm) -> Value {
    let (verdict, blocked_by, transmittance) = match light.verdict {
        LightVerdict::Unreached => ("unreached", None, None),
        LightVerdict::FacesAway => ("faces_away", None, None),
        LightVerdict::Lit => ("lit", None, Some(Color::ONE)),
        LightVerdict::Blocked { by } => ("blocked", by, Some(Color::ZERO)),
        LightVerdict::Attenuated { transmittance } => ("attenuated", None, Some(transmittance)),
    };
    let shadow_rays: Vec<Value> = light
        .shadow_rays
        .iter()
        .map(|s| {
            json!({
                "origin": xyz(s.origin),
                "direction": xyz(s.direction),
                "length": s.t_max,
                "blocker": s.blocker.map(|(id, t)| json!({
                    "object": object(scene, file, id),
                    "t": t,
                })),
                "cost": cost(s.cost),
            })
        })
        .collect();
    json!({
        "index": light.index,
        "verdict": verdict,
        "blocked_by": blocked_by.map(|id| object(scene, file, id)),
        "transmittance": transmittance.map(rgb),
        "diffuse": rgb(light.diffuse),
        "specular": rgb(light.specular),
        "shadow_rays": shadow_rays,
    })
}

fn stop_json(stop: &Stop) -> Value {
    match *stop {
        Stop::DepthLimit { max_depth } => {
            json!({ "reason": "depth_limit", "max_depth": max_depth })
        }
        Stop::Opaque => json!({ "reason": "opaque" }),
        Stop::TotalInternalReflection => json!({ "reason": "total_internal_reflection" }),
        Stop::WeightCutOff {
            kind,
            weight,
            min_weight,
        } => json!({
            "reason": "weight_cut_off",
            "ray": kind_name(kind),
            "weight": weight,
            "min_weight": min_weight,
        }),
        Stop::RayBudget { kind, budget } => json!({
            "reason": "ray_budget",
            "ray": kind_name(kind),
            "budget": budget,
        }),
    }
}
