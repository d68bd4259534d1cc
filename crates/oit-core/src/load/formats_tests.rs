//! The OBJ/MTL, PLY and STL loaders on small files written here (what exporters write, and
//! bad files refused with the line at fault), and a fuzz run over mutated files of each.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::error::OitError;
use crate::load::{load_file, LoadedFile, Surface};
use crate::primitive::Primitive;
use crate::shading::Falloff;

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("oit-core-formats-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn tmp(name: &str, data: &[u8]) -> PathBuf {
    let p = dir().join(name);
    std::fs::write(&p, data).unwrap();
    p
}

fn load(p: &Path) -> crate::error::Result<LoadedFile> {
    load_file(p, Surface::default())
}

fn message(p: &Path) -> String {
    load(p).unwrap_err().to_string()
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn obj_empty_usemtl_is_no_material() {
    tmp("plain.mtl", b"newmtl red\nKd 1 0 0\n");
    let obj = format!("mtllib plain.mtl\n{QUAD}usemtl red\nf 1 2 3\nusemtl\nf 1 3 4\nusemtl \nf 1 2 4\n");
    let f = load(&tmp("empty_usemtl.obj", obj.as_bytes())).unwrap();
    assert_eq!(f.meshes.len(), 2);
    assert_eq!(f.meshes[0].mesh.colors[0], [1.0, 0.0, 0.0, 1.0]);
    let gray = crate::load::DEFAULT_RGB;
    assert_eq!(f.meshes[1].mesh.colors[0][..3], gray);
    assert_eq!(f.meshes[1].mesh.indices.len(), 2);
}

#[test]
fn obj_lines_are_strands_and_points_particles() {
    // The box around the vertices has a diagonal of 5 (3 by 4).
    let obj = "v 0 0 0\nv 3 0 0\nv 3 4 0\nv 0 4 0\nvt 0 0\no wire\nl 1 2 3\nl 3/1 4/1\no dots\np 1 2\np -1\n";
    let f = load(&tmp("lines.obj", obj.as_bytes())).unwrap();
    assert_eq!(f.meshes.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(), ["wire", "dots"]);
    let Primitive::Strands { counts, widths } = &f.meshes[0].mesh.primitive else { panic!("{:?}", f.meshes[0].mesh.primitive) };
    assert_eq!(counts, &[3, 2]);
    assert!(widths.iter().all(|&w| (w - 5.0 / 500.0).abs() < 1e-6), "{widths:?}");
    assert_eq!(f.meshes[0].mesh.positions[3], [3.0, 4.0, 0.0]);
    let dots = &f.meshes[1].mesh;
    let Primitive::Particles { radii } = &dots.primitive else { panic!("{:?}", dots.primitive) };
    assert_eq!(dots.positions, [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]]);
    assert!(radii.iter().all(|&r| (r - 5.0 / 200.0).abs() < 1e-6), "{radii:?}");
    assert_eq!(dots.material.falloff, Falloff::Hard);
    // The point radius the caller gives wins.
    let f = crate::load::obj::read(&tmp("lines.obj", obj.as_bytes()), Some(0.5)).unwrap();
    let Primitive::Particles { radii } = &f.meshes[1].mesh.primitive else { panic!() };
    assert_eq!(radii[0], 0.5);
    // Faces, lines and points under one name are three meshes.
    let f = load(&tmp("mixed.obj", format!("{QUAD}o all\nf 1 2 3\nl 1 2\np 4\n").as_bytes())).unwrap();
    assert_eq!(f.meshes.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(), ["all", "all (lines)", "all (points)"]);
}

#[test]
fn mtl_tr_is_read_as_exporters_mean_it() {
    // MeshLab writes `Tr 1.000000` for an opaque material; `d` wins where both are written.
    let mtl = "# Converted by Meshlab Group\nnewmtl meshlab\nKd 0 1 0\nTr 1.000000\n\
               newmtl tr\nTr 0.3\nnewmtl both\nd 0.5\nTr 1\nnewmtl halo\nd -halo 0.25\nnewmtl zero\nTr 0\n";
    tmp("tr.mtl", mtl.as_bytes());
    let mut obj = format!("mtllib tr.mtl\n{QUAD}");
    for m in ["meshlab", "tr", "both", "halo", "zero"] {
        obj += &format!("o {m}\nusemtl {m}\nf 1 2 3\n");
    }
    let f = load(&tmp("tr.obj", obj.as_bytes())).unwrap();
    let alpha: Vec<f32> = f.meshes.iter().map(|m| m.mesh.colors[0][3]).collect();
    assert_eq!(alpha.len(), 5);
    assert_eq!(alpha[0], 1.0);
    assert!(f.meshes[0].mesh.opaque);
    assert!((alpha[1] - 0.7).abs() < 1e-6 && !f.meshes[1].mesh.opaque);
    assert_eq!(alpha[2..], [0.5, 0.25, 1.0]);
}

#[test]
fn obj_errors_name_the_line() {
    let e = message(&tmp("bad_index.obj", format!("# a quad\n{QUAD}f 1 2 3\nf 1 2 9\n").as_bytes()));
    assert!(e.contains("bad_index.obj: line 7: face index 9 is past the 4 vertices"), "{e}");
    let e = message(&tmp("bad_number.obj", b"v 0 0 0\nv 1 zero 0\n"));
    assert!(e.contains("line 2: y 'zero' is not a finite number"), "{e}");
    let e = message(&tmp("zero_index.obj", format!("{QUAD}f 0 1 2\n").as_bytes()));
    assert!(e.contains("line 5: face index 0"), "{e}");
    // A texture coordinate past the file's (some exporters write them): the corners lose their
    // UVs, the faces stay, and a warning says so.
    let f = load(&tmp("bad_uv.obj", format!("{QUAD}vt 0 0\nf 1/1 2/2 3/1\n").as_bytes())).unwrap();
    assert_eq!(f.meshes[0].mesh.indices.len(), 1);
    assert_eq!(f.warnings, ["1 texture coordinate indices refer past the file's texture coordinates: those corners have none"]);
    tmp("bad.mtl", b"newmtl a\n\nKd 1 x 0\n");
    let e = message(&tmp("bad_mtl.obj", format!("mtllib bad.mtl\n{QUAD}usemtl a\nf 1 2 3\n").as_bytes()));
    assert!(e.contains("bad.mtl, line 3: Kd's green 'x'"), "{e}");
}

#[test]
fn obj_missing_images_are_not_found() {
    // A missing .mtl: gray meshes and a warning, as other viewers do.
    let f = crate::load::obj::read(&tmp("no_mtl.obj", format!("mtllib nowhere.mtl\n{QUAD}usemtl x\nf 1 2 3\n").as_bytes()), None).unwrap();
    assert_eq!(f.meshes[0].mesh.colors[0][..3], crate::load::DEFAULT_RGB);
    assert_eq!(f.warnings, ["the material library 'nowhere.mtl' (line 1) named by mtllib is not there: its meshes are drawn gray"]);
    tmp("no_png.mtl", b"newmtl t\nKd 1 1 1\nmap_Kd -s 1 1 1 nowhere.png\n");
    let obj = format!("mtllib no_png.mtl\n{QUAD}vt 0 0\nusemtl t\nf 1/1 2/1 3/1\n");
    let e = load(&tmp("no_png.obj", obj.as_bytes())).unwrap_err();
    assert!(matches!(e, OitError::NotFound(_)), "{e:?}");
    assert!(e.to_string().contains("no_png.mtl, line 3: the image") && e.to_string().contains("nowhere.png is not there"), "{e}");
}

#[test]
fn obj_faces_share_vertices_and_keep_normals() {
    let obj = format!("{QUAD}vn 0 0 1\nvt 0 0\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -4//1 -2//1 -1//1\n");
    let f = load(&tmp("normals.obj", obj.as_bytes())).unwrap();
    let m = &f.meshes[0].mesh;
    assert_eq!(m.indices.len(), 3);
    // (v, vt, vn) and (v, -, vn) are different vertices.
    assert_eq!(m.positions.len(), 7);
    assert!(m.normals.iter().all(|n| *n == [0.0, 0.0, 1.0]));
}

fn ascii_stl(name: &str, n: usize) -> String {
    let mut s = format!("solid {name}\n");
    for k in 0..n {
        let z = k as f32;
        s += &format!("  facet normal 0 0 1\n    outer loop\n      vertex 0 0 {z}\n      vertex 1 0 {z}\n      vertex 0 1 {z}\n    endloop\n  endfacet\n");
    }
    s + &format!("endsolid {name}\n")
}

#[test]
fn stl_ascii_reads_every_solid_and_bare_headers() {
    let text = ascii_stl("first", 1) + &ascii_stl("second part", 2);
    let f = load(&tmp("two_solids.stl", text.as_bytes())).unwrap();
    let triangles: usize = f.meshes.iter().map(|m| m.mesh.indices.len()).sum();
    assert_eq!(triangles, 3);
    let f = load(&tmp("bare.stl", ascii_stl("", 2).as_bytes())).unwrap();
    assert_eq!(f.meshes[0].name, "bare");
    assert_eq!(f.meshes[0].mesh.indices.len(), 2);
    // Shared corners are one vertex.
    assert_eq!(f.meshes[0].mesh.positions.len(), 6);
    let e = message(&tmp("bad_ascii.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 nope\n"));
    assert!(e.contains("line 4: z 'nope' is not a finite number"), "{e}");
}

#[test]
fn stl_solids_are_meshes_of_their_own() {
    let text = ascii_stl("first", 1) + &ascii_stl("second part", 2);
    let meshes = crate::load::stl::parse(std::io::Cursor::new(text.as_bytes()), text.len() as u64, "x").unwrap();
    assert_eq!(meshes.iter().map(|m| (m.name.as_str(), m.mesh.indices.len())).collect::<Vec<_>>(), [("first", 1), ("second part", 2)]);
}

fn binary_stl(header: &[u8], facets: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut data = header.to_vec();
    data.resize(80, b' ');
    data.extend((facets.len() as u32).to_le_bytes());
    for f in facets {
        data.extend([0u8; 12]);
        f.iter().flatten().for_each(|x| data.extend(x.to_le_bytes()));
        data.extend([0, 0]);
    }
    data
}

#[test]
fn stl_binary_with_a_solid_header_is_binary() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let f = load(&tmp("solid_header.stl", &binary_stl(b"solid exported by a CAD tool", &[tri, tri]))).unwrap();
    assert_eq!(f.meshes[0].mesh.indices.len(), 2);
    // Bytes past the facets are ignored; too few are refused.
    let mut data = binary_stl(b"binary", &[tri]);
    data.extend(b"trailing");
    assert_eq!(load(&tmp("trailing.stl", &data)).unwrap().meshes[0].mesh.indices.len(), 1);
    let mut data = binary_stl(b"binary", &[tri, tri]);
    data[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = message(&tmp("huge.stl", &data));
    assert!(e.contains("4294967295 facets takes"), "{e}");
}

fn ply_header(format: &str, vertex: &str, nv: usize, face: &str, nf: usize) -> String {
    format!("ply\nformat {format} 1.0\ncomment written by a test\nelement vertex {nv}\n{vertex}element face {nf}\n{face}end_header\n")
}

#[test]
fn ply_face_colors_split_shared_vertices() {
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    let face =
        "property list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
    let text = ply_header("ascii", xyz, 4, face, 2) + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 255 0 0 255\n3 0 2 3 0 0 255 128\n";
    let f = load(&tmp("face_colors.ply", text.as_bytes())).unwrap();
    let m = &f.meshes[0].mesh;
    // The diagonal's two vertices are shared by a red and a blue face: each is split.
    assert_eq!(m.positions.len(), 6);
    assert!(!m.opaque);
    for (t, want) in m.indices.iter().zip([[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 128.0 / 255.0]]) {
        for &i in t {
            assert_eq!(m.colors[i as usize], want);
        }
    }
    // Float face colors are linear; a face's color wins over its vertices'.
    let vertex = format!("{xyz}property uchar red\nproperty uchar green\nproperty uchar blue\n");
    let face = "property list uchar int vertex_indices\nproperty float red\nproperty float green\nproperty float blue\n";
    let text = ply_header("ascii", &vertex, 3, face, 1) + "0 0 0 0 255 0\n1 0 0 0 255 0\n0 1 0 0 255 0\n3 0 1 2 0.5 0.25 0\n";
    let m = &load(&tmp("float_face.ply", text.as_bytes())).unwrap().meshes[0].mesh;
    assert_eq!(m.positions.len(), 3);
    assert!(m.colors.iter().all(|c| *c == [0.5, 0.25, 0.0, 1.0]) && m.opaque);
}

/// The same triangle pair in every binary layout: double positions, a uint16 count, int8
/// indices, a list before the positions and an extra element.
#[test]
fn ply_binary_every_type_and_endianness() {
    for (format, big) in [("binary_little_endian", false), ("binary_big_endian", true)] {
        let vertex = "property list uint8 float32 extra\nproperty double x\nproperty float32 y\nproperty int16 z\nproperty ushort red\nproperty ushort green\nproperty ushort blue\n";
        let face = "property list ushort char vertex_indices\n";
        let head = ply_header(format, vertex, 4, face, 1).replace("end_header\n", "element note 2\nproperty uint value\nend_header\n");
        let mut data = head.into_bytes();
        let put = |b: &mut Vec<u8>, bytes: &[u8]| {
            let mut v = bytes.to_vec();
            if big {
                v.reverse();
            }
            b.extend(v);
        };
        for (k, &(x, y, z)) in [(0.0f64, 0.0f32, 0i16), (1.0, 0.0, 0), (1.0, 1.0, 1), (0.0, 1.0, 1)].iter().enumerate() {
            data.push(2);
            put(&mut data, &1.5f32.to_le_bytes());
            put(&mut data, &2.5f32.to_le_bytes());
            put(&mut data, &x.to_le_bytes());
            put(&mut data, &y.to_le_bytes());
            put(&mut data, &z.to_le_bytes());
            for c in [65535u16, 0, (k as u16) * 1000] {
                put(&mut data, &c.to_le_bytes());
            }
        }
        put(&mut data, &4u16.to_le_bytes());
        data.extend([0u8, 1, 2, 3]);
        put(&mut data, &7u32.to_le_bytes());
        put(&mut data, &8u32.to_le_bytes());
        let f = load(&tmp(&format!("{format}.ply"), &data)).unwrap();
        let m = &f.meshes[0].mesh;
        assert_eq!(m.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 1.0], [0.0, 1.0, 1.0]], "{format}");
        assert_eq!(m.indices, [[0, 1, 2], [0, 2, 3]], "{format}");
        assert_eq!(m.colors[0], [1.0, 0.0, 0.0, 1.0], "{format}");
        // Cut short by one byte: refused, not padded.
        let e = message(&tmp(&format!("short_{format}.ply"), &data[..data.len() - 1]));
        assert!(e.contains("note 1: the file ends inside its data (cut short?)"), "{e}");
    }
}

#[test]
fn ply_huge_counts_are_refused_before_allocating() {
    let start = Instant::now();
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    let text = ply_header("binary_little_endian", xyz, 4_000_000_000, "property list uchar int vertex_indices\n", 1);
    let e = message(&tmp("huge_count.ply", text.as_bytes()));
    assert!(e.contains("need at least 48000000001 bytes of data, the file has 0"), "{e}");
    let text = ply_header("ascii", xyz, 3, "property list uint int vertex_indices\n", 1) + "0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
    let e = message(&tmp("huge_list.ply", text.as_bytes()));
    assert!(e.contains("line 14: face 0: a list of 4000000000 values does not fit"), "{e}");
    let text = ply_header("ascii", xyz, 3, "property list uchar int vertex_indices\n", 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    let e = message(&tmp("bad_face.ply", text.as_bytes()));
    assert!(e.contains("face 0: vertex index 7 is past the 3 vertices"), "{e}");
    assert!(start.elapsed() < Duration::from_secs(1));
}

#[test]
fn decimals_parse_as_the_standard_parser_does() {
    let mut rng = XorShiftStar(7);
    for _ in 0..100_000 {
        let digits = 1 + rng.below(12);
        let mut s: String = (0..digits).map(|_| (b'0' + rng.below(10) as u8) as char).collect();
        if rng.below(2) == 0 {
            s.insert(rng.below(s.len() + 1), '.');
        }
        if rng.below(3) == 0 {
            s += &format!("e{}", rng.below(30) as i32 - 15);
        }
        if rng.below(2) == 0 {
            s.insert(0, '-');
        }
        let want = s.parse::<f64>().ok();
        if let Some(got) = crate::load::text::decimal(s.as_bytes()) {
            assert_eq!(Some(got), want, "{s}");
        }
    }
    assert_eq!(crate::load::text::decimal(b"12345678901234567890123"), None);
    assert_eq!(crate::load::text::decimal(b"1e"), None);
}

/// A small deterministic generator (xorshift64*).
struct XorShiftStar(u64);

impl XorShiftStar {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn mutate(rng: &mut XorShiftStar, data: &[u8]) -> Vec<u8> {
    let mut d = data.to_vec();
    const HUGE: [&[u8]; 8] = [b"4294967295", b"4294967296", b"-1", b"99999999999999999999", b"2147483648", b"nan", b"1e39", b"0"];
    for _ in 0..1 + rng.below(3) {
        match rng.below(6) {
            0 => d.truncate(rng.below(d.len() + 1)),
            1 => {
                for _ in 0..1 + rng.below(8) {
                    if !d.is_empty() {
                        let i = rng.below(d.len());
                        d[i] ^= 1 << rng.below(8);
                    }
                }
            }
            2 | 3 => {
                // A number (or a token) swapped for a huge or odd one.
                let starts: Vec<usize> =
                    (0..d.len()).filter(|&i| d[i].is_ascii_digit() && (i == 0 || !d[i - 1].is_ascii_digit())).collect();
                if let Some(&i) = starts.get(rng.below(starts.len())) {
                    let end = (i..d.len()).find(|&k| !d[k].is_ascii_digit()).unwrap_or(d.len());
                    d.splice(i..end, HUGE[rng.below(HUGE.len())].iter().copied());
                }
            }
            4 => {
                // Four bytes somewhere set to a huge little-endian count.
                if d.len() >= 4 {
                    let i = rng.below(d.len() - 3);
                    d[i..i + 4].copy_from_slice(&[0xff, 0xff, 0xff, rng.below(256) as u8]);
                }
            }
            _ => {
                if !d.is_empty() {
                    let (a, b) = (rng.below(d.len()), rng.below(d.len()));
                    let piece = d[a.min(b)..a.max(b)].to_vec();
                    let at = rng.below(d.len());
                    d.splice(at..at, piece);
                }
            }
        }
    }
    d
}

/// Mutated OBJ/MTL, PLY (ASCII, both binaries) and STL (ASCII, binary) files: every load ends
/// in a value or an error, never a panic, each within a second.
#[test]
fn fuzzed_files_never_panic_or_hang() {
    let d = dir().join("fuzz");
    std::fs::create_dir_all(&d).unwrap();
    let xyz = "property float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n";
    let face = "property list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n";
    let ply_ascii =
        ply_header("ascii", xyz, 4, face, 2) + "0 0 0 1 2 3\n1 0 0 4 5 6\n1 1 0 7 8 9\n0 1 0 1 1 1\n3 0 1 2 255 0 0\n4 0 1 2 3 0 255 0\n";
    let mut ply_binary = ply_header("binary_little_endian", xyz, 3, face, 1).into_bytes();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        p.iter().for_each(|x| ply_binary.extend(x.to_le_bytes()));
        ply_binary.extend([10, 20, 30]);
    }
    ply_binary.push(3);
    [0i32, 1, 2].iter().for_each(|i| ply_binary.extend(i.to_le_bytes()));
    ply_binary.extend([255, 0, 0]);
    let ply_big = String::from_utf8_lossy(&ply_binary).replace("binary_little_endian", "binary_big_endian").into_bytes();
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mtl = b"newmtl a\nKd 1 0.5 0\nd 0.5\nnewmtl b\nTr 1.000000\nmap_d -s 1 1 1 missing.png\n".to_vec();
    let obj = format!("mtllib f.mtl\n{QUAD}vt 0 0\nvn 0 0 1\no a\nusemtl a\nf 1/1/1 2/1/1 3/1/1 4/1/1\nl 1 2 3\np 4 -1\ng b\nusemtl b\nf -1 -2 -3\nusemtl\nf 1//1 2//1 3//1\n");
    let bases: Vec<(&str, Vec<u8>)> = vec![
        ("f.obj", obj.into_bytes()),
        ("f.mtl", mtl),
        ("a.ply", ply_ascii.into_bytes()),
        ("b.ply", ply_binary),
        ("c.ply", ply_big),
        ("a.stl", (ascii_stl("one", 2) + &ascii_stl("", 1)).into_bytes()),
        ("b.stl", binary_stl(b"solid but binary", &[tri, tri, tri])),
    ];
    for (name, data) in &bases {
        std::fs::write(d.join(name), data).unwrap();
    }
    let mut rng = XorShiftStar(0x0123_4567_89ab_cdef);
    let start = Instant::now();
    let mut runs = 0;
    while start.elapsed() < Duration::from_secs(4) {
        let (name, data) = &bases[rng.below(bases.len())];
        let mutated = mutate(&mut rng, data);
        std::fs::write(d.join(name), &mutated).unwrap();
        let target = if *name == "f.mtl" { d.join("f.obj") } else { d.join(name) };
        let one = Instant::now();
        let result = std::panic::catch_unwind(|| load(&target).map(|f| f.meshes.len()));
        assert!(result.is_ok(), "{name} panicked on {:?}", String::from_utf8_lossy(&mutated));
        assert!(one.elapsed() < Duration::from_secs(1), "{name} took {:?} on {:?}", one.elapsed(), String::from_utf8_lossy(&mutated));
        std::fs::write(d.join(name), data).unwrap();
        runs += 1;
    }
    eprintln!("{runs} mutated files loaded");
    assert!(runs > 500, "only {runs} files in the time");
}

/// The load speed check (not run by default): `OIT_BENCH_DIR=dir` writes a 1.3 M-triangle grid
/// in each format there; `OIT_BENCH_FILE=file` loads one and prints the time and the peak
/// resident memory (one process a file, so each peak is its own).
#[test]
#[ignore]
fn load_speed() {
    use std::io::Write;
    if let Ok(dir) = std::env::var("OIT_BENCH_DIR") {
        let dir = PathBuf::from(dir);
        let n = 806;
        let vertex = |i: usize, j: usize| [i as f32 / n as f32, j as f32 / n as f32, ((i * 7 + j * 3) % 11) as f32 / 1000.0];
        let mut faces = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let a = (i * n + j) as u32;
                faces.push([a, a + 1, a + n as u32 + 1]);
                faces.push([a, a + n as u32 + 1, a + n as u32]);
            }
        }
        let points: Vec<[f32; 3]> = (0..n * n).map(|k| vertex(k / n, k % n)).collect();
        let file = |name: &str| std::io::BufWriter::new(std::fs::File::create(dir.join(name)).unwrap());
        let mut obj = file("grid.obj");
        points.iter().for_each(|p| writeln!(obj, "v {} {} {}", p[0], p[1], p[2]).unwrap());
        faces.iter().for_each(|f| writeln!(obj, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap());
        let head = |format: &str| {
            format!("ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n", points.len(), faces.len())
        };
        let mut ply = file("grid.ply");
        ply.write_all(head("binary_little_endian").as_bytes()).unwrap();
        points.iter().flatten().for_each(|x| ply.write_all(&x.to_le_bytes()).unwrap());
        for f in &faces {
            ply.write_all(&[3]).unwrap();
            f.iter().for_each(|i| ply.write_all(&i.to_le_bytes()).unwrap());
        }
        let mut ply = file("grid_ascii.ply");
        ply.write_all(head("ascii").as_bytes()).unwrap();
        points.iter().for_each(|p| writeln!(ply, "{} {} {}", p[0], p[1], p[2]).unwrap());
        faces.iter().for_each(|f| writeln!(ply, "3 {} {} {}", f[0], f[1], f[2]).unwrap());
        let corners = |f: &[u32; 3]| f.map(|i| points[i as usize]);
        file("grid.stl").write_all(&binary_stl(b"grid", &faces.iter().map(corners).collect::<Vec<_>>())).unwrap();
        let mut stl = file("grid_ascii.stl");
        writeln!(stl, "solid grid").unwrap();
        for f in &faces {
            writeln!(stl, "facet normal 0 0 1\nouter loop").unwrap();
            corners(f).iter().for_each(|p| writeln!(stl, "vertex {} {} {}", p[0], p[1], p[2]).unwrap());
            writeln!(stl, "endloop\nendfacet").unwrap();
        }
        writeln!(stl, "endsolid grid").unwrap();
    }
    if let Ok(path) = std::env::var("OIT_BENCH_FILE") {
        let p = Path::new(&path);
        let start = Instant::now();
        match p.extension().filter(|_| std::env::var("OIT_BENCH_ALONE").is_ok()).and_then(|e| e.to_str()) {
            Some("obj") => drop(crate::load::obj::read(p, None).unwrap()),
            Some("ply") => drop(crate::load::ply::load_ply(p).unwrap()),
            Some(_) => drop(crate::load::stl::read(p).unwrap()),
            None => {}
        }
        eprintln!("the format's reader alone: {:.3} s", start.elapsed().as_secs_f64());
        let start = Instant::now();
        let f = load(Path::new(&path)).unwrap();
        let seconds = start.elapsed().as_secs_f64();
        let triangles: usize = f.meshes.iter().map(|m| m.mesh.indices.len()).sum();
        let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
        let peak = status.lines().find(|l| l.starts_with("VmHWM")).unwrap_or("VmHWM: ?");
        let bytes: usize = f
            .meshes
            .iter()
            .map(|m| m.mesh.positions.len() * 12 + m.mesh.indices.len() * 12 + m.mesh.colors.len() * 16 + m.mesh.normals.len() * 12)
            .sum();
        eprintln!(
            "{path}: {triangles} triangles in {seconds:.3} s = {:.2} M triangles/s; {peak}; mesh arrays {:.1} MB",
            triangles as f64 / seconds / 1e6,
            bytes as f64 / 1e6
        );
    }
}
