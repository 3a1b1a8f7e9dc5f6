//! Scenes with instances through the binary: a TOML file including one mesh
//! several times, and the generated forest up to 10⁹ instanced triangles;
//! `info` and the render caption say what is instanced, and `bench` times
//! every engine through its instances.

use crate::support::cli::{raypack, stderr};
use crate::support::scratch::Scratch;

/// A TOML scene placing `part.nff` (two triangles) three times, once through
/// a file that includes it in turn (two instance levels).
fn three_parts() -> Scratch {
    let dir = Scratch::new("cli-instances");
    dir.write(
        "part.nff",
        "f 1 0 0 1 0 0 0 1\np 3\n0 0 0\n1 0 0\n0 1 0\np 3\n1 0 0\n1 1 0\n0 1 0\n",
    );
    dir.write(
        "pair.toml",
        "[[objects]]\ntype = \"include\"\npath = \"part.nff\"\ntransform = { translate = [0, 2, 0] }\n",
    );
    dir.write(
        "main.toml",
        r#"
[camera]
eye = [0.5, 1.5, 6]
center = [0.5, 1.5, 0]
fovx = 50
fovy = 50
width = 64
height = 64

[[lights]]
position = [0, 0, 10]

[[objects]]
type = "include"
path = "part.nff"

[[objects]]
type = "include"
path = "part.nff"
transform = { translate = [-2, 0, 0], rotate = { axis = [0, 0, 1], degrees = 30 } }

[[objects]]
type = "include"
path = "pair.toml"
"#,
    );
    dir
}

#[test]
fn info_and_render_say_what_is_instanced() {
    let dir = three_parts();
    let main = dir.path().join("main.toml");
    let main = main.to_str().unwrap();
    let o = raypack(&["info", main]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("primitives  6\n"), "{text}");
    // part.nff is one mesh (placed twice directly), and one more through pair.toml.
    assert!(
        text.contains("instances   3 instances of 2 meshes (depth 2): 4 unique, 6 instanced primitives\n"),
        "{text}"
    );
    let json = raypack(&["info", main, "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(json["instancing"]["instances"], 3);
    assert_eq!(json["instancing"]["instanced_primitives"], 6);

    let png = dir.path().join("out.png");
    let stats = dir.path().join("out.json");
    let (png, stats) = (png.to_str().unwrap(), stats.to_str().unwrap());
    for kernel in ["scalar", "packet8", "packet16"] {
        let o = raypack(&[
            "render",
            main,
            "-o",
            png,
            "--kernel",
            kernel,
            "--stats-json",
            stats,
        ]);
        assert!(o.status.success(), "{kernel}: {}", stderr(&o));
        let report: serde_json::Value = serde_json::from_slice(&std::fs::read(stats).unwrap()).unwrap();
        assert_eq!(report["primitives"], 6);
        assert_eq!(report["instancing"]["depth"], 2);
        assert!(
            report["rays"]["eye_hits"].as_u64().unwrap() > 64 * 64 / 20,
            "{report}"
        );
    }
}

#[test]
fn a_billion_instanced_triangles_load_and_render() {
    let dir = Scratch::new("cli-forest");
    let json = raypack(&["info", "gen:forest:56000", "--json"]);
    assert!(json.status.success(), "{}", stderr(&json));
    let json: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let instancing = &json["instancing"];
    assert!(
        instancing["instanced_primitives"].as_u64().unwrap() > 1_000_000_000,
        "{json}"
    );
    assert!(
        instancing["unique_primitives"].as_u64().unwrap() < 30_000,
        "{json}"
    );
    let png = dir.path().join("forest.png");
    let o = raypack(&[
        "render",
        "gen:forest:56000",
        "-o",
        png.to_str().unwrap(),
        "--size",
        "96x96",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // `trace` answers nearest hits through the instances too: flattened, the
    // scene would be 10⁹ primitives, which it refuses to make. A ray straight
    // down from high above the forest's middle meets a tree, a rock or the
    // ground; one pointing up meets nothing.
    let rays = dir.path().join("rays.csv");
    std::fs::write(
        &rays,
        "ox,oy,oz,dx,dy,dz,tmin,tmax\n470,500,470,0,-1,0,0,inf\n470,500,470,0,1,0,0,inf\n",
    )
    .unwrap();
    let hits = dir.path().join("hits.csv");
    let o = raypack(&[
        "trace",
        "gen:forest:56000",
        "--rays",
        rays.to_str().unwrap(),
        "--out",
        hits.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let hits = std::fs::read_to_string(&hits).unwrap();
    let lines: Vec<&str> = hits.lines().collect();
    assert_eq!(lines.len(), 3, "{hits}");
    let (t, prim) = lines[1].split_once(',').unwrap();
    let t: f32 = t.parse().unwrap();
    assert!(t > 480.0 && t <= 500.0 && prim != "-1", "{hits}");
    assert_eq!(lines[2], "inf,-1", "{hits}");
    // `--query all` reads every primitive as a copy, which a scene this large
    // cannot be made into: refused, saying which query needs the copies and
    // nothing written.
    let all = dir.path().join("all.csv");
    let o = raypack(&[
        "trace",
        "gen:forest:56000",
        "--rays",
        rays.to_str().unwrap(),
        "--query",
        "all",
        "--out",
        all.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let message = stderr(&o);
    assert!(
        message.contains("trace --query all reads every primitive as a copy")
            && message.contains("flattening the scene into copies would make")
            && !message.contains("no instances of its own"),
        "{message}"
    );
    assert!(!all.exists(), "nothing half-written");
}

#[test]
fn bench_scene_times_instanced_scenes() {
    let o = raypack(&[
        "bench",
        "scene",
        "gen:forest:200",
        "--size",
        "48x48",
        "--runs",
        "1",
        "--threads",
        "1",
        "--rays",
        "primary,shadow,random",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let result: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = result["rows"].as_array().unwrap();
    assert!(!rows.is_empty());
    for row in rows {
        assert!(row["median"].as_f64().unwrap() > 0.0, "{row}");
    }
}

#[test]
fn bench_scene_heads_its_table_with_the_instanced_counts_info_gives() {
    let info = raypack(&["info", "gen:forest:20", "--json"]);
    assert!(info.status.success(), "{}", stderr(&info));
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let count = |key: &str| info["instancing"][key].as_u64().unwrap();
    let o = raypack(&[
        "bench",
        "scene",
        "gen:forest:20",
        "--size",
        "16x16",
        "--runs",
        "1",
        "--threads",
        "1",
        "--rays",
        "primary",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let head = String::from_utf8(o.stdout).unwrap();
    let head = head.lines().next().unwrap().to_owned();
    // Every id the rays may hit, then the unique primitives and the instances.
    let expected = format!(
        "gen:forest:20: {} primitives ({} unique, 20 instances), 16x16 primary rays",
        count("instanced_primitives"),
        count("unique_primitives"),
    );
    assert!(head.starts_with(&expected), "{head}\nexpected {expected}");
}

#[test]
fn a_bad_instance_transform_names_the_include() {
    let dir = Scratch::new("cli-instances-bad");
    dir.write("part.nff", "p 3\n0 0 0\n1 0 0\n0 1 0\n");
    let main = dir.write(
        "main.toml",
        "[[objects]]\ntype = \"include\"\npath = \"part.nff\"\ntransform = { scale = [1, 0, 1] }\n",
    );
    let o = raypack(&["info", main.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("main.toml:4") && e.contains("singular"), "{e}");
    assert!(o.stdout.is_empty());
}

/// `gen forest` and `gen city` write glTF (binary or JSON by the file name,
/// JSON to stdout), which `info` reads back as the same instances as
/// `gen:forest` and `gen:city`;
/// NFF, which has no instances, is refused, as is glTF for a scene of
/// spheres on a polygon floor, each with nothing written.
#[test]
fn gen_writes_instanced_scenes_as_gltf_that_reads_back_as_the_same_instances() {
    let dir = Scratch::new("cli-gen-forest");
    let instancing = |scene: &str| {
        let o = raypack(&["info", scene, "--json"]);
        assert!(o.status.success(), "{scene}: {}", stderr(&o));
        let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        json["instancing"].clone()
    };
    // Each instanced kind, with its meshes as `gen` makes them.
    for (kind, instances, meshes) in [("forest", 300, 2), ("city", 120, 4)] {
        let expected = instancing(&format!("gen:{kind}:{instances}:7"));
        assert_eq!(expected["instances"], instances, "{expected}");
        for name in [format!("{kind}.glb"), format!("{kind}.gltf")] {
            let path = dir.path().join(&name);
            let size = instances.to_string();
            let o = raypack(&[
                "gen",
                kind,
                "--size",
                &size,
                "--seed",
                "7",
                "-o",
                path.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
            let got = instancing(path.to_str().unwrap());
            // The ground, the scene's own two triangles, reads back as one more
            // instance of a mesh of its own.
            assert_eq!(got["instances"], instances + 1, "{name}: {got}");
            assert_eq!(got["meshes"], meshes + 1, "{name}: {got}");
            for count in ["unique_primitives", "instanced_primitives"] {
                assert_eq!(got[count], expected[count], "{name}: {count}");
            }
        }
    }
    let o = raypack(&["gen", "forest", "--size", "20"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["asset"]["version"], "2.0");

    // NFF's triangles (`p 3`) are glTF's: a generated mesh reads back whole.
    let mesh = dir.path().join("triangles.glb");
    let o = raypack(&[
        "gen",
        "random-triangles",
        "--size",
        "50",
        "-o",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info = raypack(&["info", mesh.to_str().unwrap(), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(json["instancing"]["instanced_primitives"], 50, "{json}");

    for (args, message, file) in [
        (["gen", "forest", "-o"], "NFF cannot hold", "forest.nff"),
        (
            ["gen", "sphereflake", "-o"],
            "primitive 0 is a polygon",
            "balls.glb",
        ),
    ] {
        let path = dir.path().join(file);
        let mut args = args.to_vec();
        args.push(path.to_str().unwrap());
        let o = raypack(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
        assert!(!path.exists(), "{args:?} wrote {}", path.display());
    }
}
