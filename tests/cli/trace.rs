//! `raypack trace`: rays CSV in, hits CSV out, through raypack; clear errors
//! (exit 2) for bad input, and no half-written output.

use std::path::PathBuf;

use raypack::accel::{Accel, BruteForce};
use raypack::compare::csv::format_rays;
use raypack::compare::random_rays;
use raypack::scene::generate::test_scenes;

use crate::support::cli::{scratch, stderr, trace};

#[test]
fn trace_writes_one_hit_per_ray_in_file_order() {
    let dir = scratch("trace");
    let scene = test_scenes::by_name("mixed", 120, 5).unwrap();
    let rays = random_rays(scene.bounds(), 500, 2);
    std::fs::write(dir.join("rays.csv"), format_rays(&rays)).unwrap();
    let out = dir.join("hits.csv");
    let o = trace("gen:mixed:120:5", &dir.join("rays.csv"), &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,prim"));
    let accel = BruteForce::new(&scene.primitives);
    let mut hits = 0;
    for (ray, line) in rays.iter().zip(lines.by_ref()) {
        // The file's rays went through text and back: trace what was read.
        let ray = raypack::compare::csv::parse_rays("r", &format_rays(&[*ray])).unwrap()[0];
        let expected = accel.intersect(&ray);
        let (t, prim) = line.split_once(',').unwrap();
        if expected.is_hit() {
            assert_eq!(
                (t.parse::<f32>().unwrap(), prim.parse::<u32>().unwrap()),
                (expected.t, expected.prim)
            );
            hits += 1;
        } else {
            assert_eq!(line, "inf,-1");
        }
    }
    assert_eq!(lines.next(), None, "one line per ray");
    assert!(hits > 100 && hits < rays.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_exits_2_with_file_and_line_and_writes_nothing() {
    let dir = scratch("trace-bad");
    let out = dir.join("hits.csv");
    std::fs::write(
        dir.join("bad.csv"),
        "ox,oy,oz,dx,dy,dz,tmin,tmax\n0,0,0,1,0,0,0,inf\n0,0,0,1,0\n",
    )
    .unwrap();
    let cases: [(&str, PathBuf, &str); 3] = [
        (
            "gen:mixed:50",
            dir.join("bad.csv"),
            "bad.csv:3: expected 8 numbers",
        ),
        (
            "gen:mixed:50",
            dir.join("missing.csv"),
            "missing.csv: cannot read",
        ),
        (
            "gen:cubes",
            dir.join("bad.csv"),
            "unknown generated scene `cubes`",
        ),
    ];
    for (scene, rays, message) in cases {
        let output = trace(scene, &rays, &out, &[]);
        let stderr = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(message), "{stderr:?} should say {message:?}");
        assert!(!out.exists(), "no output file on bad input");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(not(feature = "embree"))]
#[test]
fn embree_without_the_feature_is_a_clear_error() {
    use crate::support::cli::raypack;
    let dir = scratch("trace-noembree");
    std::fs::write(
        dir.join("rays.csv"),
        "ox,oy,oz,dx,dy,dz,tmin,tmax\n0,0,9,0,0,-1,0,inf\n",
    )
    .unwrap();
    let output = trace(
        "gen:spheres:10",
        &dir.join("rays.csv"),
        &dir.join("hits.csv"),
        &["--engine", "embree"],
    );
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("built without the `embree` feature"));
    let output = raypack(&["check", "gen:spheres:10"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("scripts/install-embree.sh"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn diff_classifies_the_rays_on_which_another_engines_hits_differ() {
    let dir = scratch("trace-diff");
    let scene = test_scenes::by_name("mixed", 120, 5).unwrap();
    let rays = random_rays(scene.bounds(), 300, 3);
    std::fs::write(dir.join("rays.csv"), format_rays(&rays)).unwrap();
    let trace = |diff: Option<&PathBuf>| {
        let diff = diff.map(|d| d.to_str().unwrap());
        let extra = diff.map(|d| vec!["--diff", d]).unwrap_or_default();
        trace(
            "gen:mixed:120:5",
            &dir.join("rays.csv"),
            &dir.join("hits.csv"),
            &extra,
        )
    };
    assert!(trace(None).status.success());
    let ours = std::fs::read_to_string(dir.join("hits.csv")).unwrap();
    // Against itself: everything agrees.
    let same = dir.join("same.csv");
    std::fs::write(&same, &ours).unwrap();
    let o = trace(Some(&same));
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.starts_with("300 rays compared with "), "{text}");
    assert!(text.lines().skip(1).all(|l| l.ends_with(" 0")), "{text}");
    // Another engine's file with one miss, one other primitive and one t far off.
    let mut lines: Vec<String> = ours.lines().map(String::from).collect();
    let hit_rows: Vec<usize> = (1..lines.len())
        .filter(|&i| lines[i] != "inf,-1")
        .take(3)
        .collect();
    let (t, prim) = lines[hit_rows[1]]
        .split_once(',')
        .map(|(t, p)| (t.to_string(), p.to_string()))
        .unwrap();
    lines[hit_rows[0]] = "inf,-1".into();
    let other_prim = (prim.parse::<u32>().unwrap() + 1) % 120;
    lines[hit_rows[1]] = format!("{},{other_prim}", t.parse::<f32>().unwrap() * 2.0);
    let (t, prim) = lines[hit_rows[2]]
        .split_once(',')
        .map(|(t, p)| (t.to_string(), p.to_string()))
        .unwrap();
    lines[hit_rows[2]] = format!("{},{prim}", t.parse::<f32>().unwrap() * 1.001);
    let other = dir.join("other.csv");
    std::fs::write(&other, lines.join("\n") + "\n").unwrap();
    let o = trace(Some(&other));
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    for line in [
        "hit only by raypack",
        "different primitive",
        "same primitive, t > 16 ulps apart",
    ] {
        let count = text.lines().find(|l| l.trim_start().starts_with(line)).unwrap();
        assert!(count.ends_with(" 1"), "{line}: {text}");
    }
    // A file of another length is refused, naming both files.
    std::fs::write(&other, "t,prim\ninf,-1\n").unwrap();
    let o = trace(Some(&other));
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("other.csv: 1 hit for 300 rays: expected one line per ray"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
