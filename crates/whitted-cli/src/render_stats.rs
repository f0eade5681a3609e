//! The breakdown `whitted render --stats` prints: where a render's time
//! went (reading the scene, building the world, the photon pass, tracing,
//! writing the files) and the rays by kind with their rates.

use whitted::render::RenderOutput;

/// The stages the command times around the library's render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageSeconds {
    /// Reading and checking the scene file (0 for the built-in scene).
    pub load: f64,
    /// The whole `render` call: world, photons and tracing.
    pub render: f64,
    /// Encoding and writing the output files.
    pub write: f64,
}

/// The lines of the breakdown.
pub fn lines(output: &RenderOutput, stages: StageSeconds) -> Vec<String> {
    let trace = &output.trace;
    let photon_seconds = output.photons.as_ref().map_or(0.0, |p| p.seconds);
    let mut lines = vec!["stats:".to_string()];
    let mut stage = |name: &str, seconds: f64, what: String| {
        lines.push(format!("  {name:<8}{seconds:>9.3} s  {what}"));
    };
    stage("load", stages.load, "reading the scene".to_string());
    stage(
        "build",
        output.build_seconds,
        "building the acceleration structures".to_string(),
    );
    if let Some(photons) = &output.photons {
        stage(
            "photons",
            photon_seconds,
            format!(
                "{} photons shot, {} stored",
                photons.emitted, photons.stored
            ),
        );
    }
    stage(
        "trace",
        trace.seconds,
        format!(
            "{} tiles on {} thread{}, busy {:.1}% of the time; the first thread out of tiles \
             waited {:.3} s for the others",
            trace.tiles,
            trace.threads,
            if trace.threads == 1 { "" } else { "s" },
            trace.utilisation() * 100.0,
            trace.tail_seconds
        ),
    );
    let other = stages.render - output.build_seconds - photon_seconds - trace.seconds;
    stage(
        "other",
        other.max(0.0),
        "checks, films and merging the tiles".to_string(),
    );
    stage(
        "write",
        stages.write,
        "encoding and writing the files".to_string(),
    );
    stage(
        "total",
        stages.load + stages.render + stages.write,
        "(the summary line's time is build + photons + trace + other)".to_string(),
    );
    let total: u64 = output.rays.total();
    for &kind in output.ray_kinds {
        let count = output.rays[kind];
        lines.push(format!(
            "  {:<10}{count:>12} rays  {:>5.1}%  {:>8.2} Mrays/s of trace time",
            kind.name(),
            share(count, total) * 100.0,
            rate(count, trace.seconds),
        ));
    }
    lines.push(format!(
        "  {:<10}{total:>12} rays  100.0%  {:>8.2} Mrays/s of trace time",
        "all",
        rate(total, trace.seconds),
    ));
    lines
}

fn share(count: u64, total: u64) -> f64 {
    if total == 0 {
        0.0
    } else {
        count as f64 / total as f64
    }
}

fn rate(count: u64, seconds: f64) -> f64 {
    if seconds > 0.0 {
        count as f64 / seconds / 1e6
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted::render::render;

    #[test]
    fn every_stage_and_every_kind_of_ray_is_listed_and_the_rays_add_up() {
        let mut scene = whitted::scene::default_scene();
        scene.settings.width = 32;
        scene.settings.height = 24;
        scene.settings.threads = Some(1);
        let output = render(&scene, &|_| {}).unwrap();
        let lines = lines(
            &output,
            StageSeconds {
                load: 0.5,
                render: 10.0,
                write: 0.25,
            },
        );
        let text = lines.join("\n");
        for stage in ["load", "build", "trace", "other", "write", "total"] {
            assert!(text.contains(&format!("\n  {stage} ")), "{text}");
        }
        assert!(!text.contains("\n  photons "), "{text}");
        assert!(text.contains("  total      10.750 s"), "{text}");
        let primary = output.rays[whitted::integrator::RayKind::Primary];
        assert_eq!(primary, 32 * 24);
        assert!(
            text.contains(&format!("primary   {primary:>12} rays")),
            "{text}"
        );
        let all = lines.last().unwrap();
        assert!(
            all.contains(&format!("{:>12} rays  100.0%", output.rays.total())),
            "{all}"
        );
    }
}
