//! The node tree: each node's local transform (matrix or TRS), the walk from the scene's roots
//! in file order with each node's world transform, and EXT_mesh_gpu_instancing. A node graph
//! that is not a forest (a node with two parents, a cycle) is refused naming the node; the walk
//! keeps a visited set and a depth bound besides, so no file can make it loop.

use glam::{DMat4, DQuat, DVec3};

use super::data::Store;
use super::json::Obj;

/// The deepest a node tree may nest.
const MAX_DEPTH: usize = 1 << 16;

/// A node's transform relative to its parent.
pub(super) fn local(node: &Obj<'_>) -> Result<DMat4, String> {
    if let Some(m) = node.nums::<16>("matrix")? {
        return Ok(DMat4::from_cols_array(&m));
    }
    let t = node.nums::<3>("translation")?.unwrap_or([0.0; 3]);
    let s = node.nums::<3>("scale")?.unwrap_or([1.0; 3]);
    let r = node.nums::<4>("rotation")?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    Ok(DMat4::from_scale_rotation_translation(DVec3::from(s), rotation(r, &node.at)?, DVec3::from(t)))
}

/// A quaternion (x, y, z, w), renormalized; a zero one is refused.
fn rotation(r: [f64; 4], at: &str) -> Result<DQuat, String> {
    let q = DQuat::from_array(r);
    let len = q.length();
    if len.is_nan() || len <= 1e-6 {
        return Err(format!("{at}: rotation {r:?} is not a unit quaternion"));
    }
    Ok(q / len)
}

/// The nodes to draw, parents before children, in file order, each with its world transform.
/// `scene` is the document's `scene` (or scenes[0]; with no scenes, every root node).
pub(super) fn walk(root: &Obj<'_>, nodes: &[Obj<'_>], scenes: &[Obj<'_>]) -> Result<Vec<(usize, DMat4)>, String> {
    let n = nodes.len();
    let mut children = Vec::with_capacity(n);
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (i, node) in nodes.iter().enumerate() {
        let list = node.indices("children", n, "nodes")?;
        for &c in &list {
            if c == i {
                return Err(format!("nodes[{i}] is its own child: a node tree has no cycles"));
            }
            if let Some(p) = parent[c] {
                return Err(format!("nodes[{c}] has two parents, nodes[{p}] and nodes[{i}]: a node has at most one parent"));
            }
            parent[c] = Some(i);
        }
        children.push(list);
    }
    // With one parent each, a cycle is a chain of parents that comes back to where it began.
    let mut state = vec![0u8; n]; // 0 unseen, 1 on the chain being followed, 2 known to end at a root
    for start in 0..n {
        let mut chain = Vec::new();
        let mut at = Some(start);
        while let Some(i) = at {
            match state[i] {
                2 => break,
                1 => return Err(format!("nodes[{i}] is its own ancestor: the nodes' children form a cycle")),
                _ => {}
            }
            state[i] = 1;
            chain.push(i);
            at = parent[i];
        }
        chain.into_iter().for_each(|i| state[i] = 2);
    }
    let roots = match root.index("scene", scenes.len(), "scenes")?.or((!scenes.is_empty()).then_some(0)) {
        Some(s) => {
            let roots = scenes[s].indices("nodes", n, "nodes")?;
            if let Some(&r) = roots.iter().find(|&&r| parent[r].is_some()) {
                return Err(format!(
                    "scenes[{s}].nodes lists nodes[{r}], a child of nodes[{}]: a scene lists root nodes only",
                    parent[r].unwrap_or(0)
                ));
            }
            roots
        }
        None => (0..n).filter(|&i| parent[i].is_none()).collect(),
    };
    let mut visited = vec![false; n];
    let mut out = Vec::new();
    let mut stack: Vec<(usize, DMat4, usize)> = roots.iter().rev().map(|&r| (r, DMat4::IDENTITY, 0)).collect();
    while let Some((i, above, depth)) = stack.pop() {
        if std::mem::replace(&mut visited[i], true) {
            return Err(format!("nodes[{i}] is reached twice from the scene's roots: a node is drawn from one place"));
        }
        if depth > MAX_DEPTH {
            return Err(format!("nodes[{i}] lies {depth} levels deep, past the {MAX_DEPTH} oit walks"));
        }
        let world = above * local(&nodes[i])?;
        stack.extend(children[i].iter().rev().map(|&c| (c, world, depth + 1)));
        out.push((i, world));
    }
    Ok(out)
}

/// An instancing attribute's values and its accessor's name.
type Attribute<const N: usize> = (Vec<[f32; N]>, String);

/// A node's placements: its world transform, or with EXT_mesh_gpu_instancing that times each
/// instance's TRS (attributes TRANSLATION, ROTATION, SCALE; missing ones the identity).
pub(super) fn instances(node: &Obj<'_>, world: DMat4, store: &Store<'_>) -> Result<Vec<DMat4>, String> {
    let Some(ext) = node.extension("EXT_mesh_gpu_instancing")? else { return Ok(vec![world]) };
    let Some(attrs) = ext.obj("attributes")? else { return Ok(vec![world]) };
    let n = store.accessor_count();
    let read3 = |key: &str| -> Result<Option<Attribute<3>>, String> {
        let Some(i) = attrs.index(key, n, "accessors")? else { return Ok(None) };
        let a = store.accessor(i)?;
        Ok(Some((a.floats::<3>(store)?, a.at)))
    };
    let t = read3("TRANSLATION")?;
    let s = read3("SCALE")?;
    let r = match attrs.index("ROTATION", n, "accessors")? {
        Some(i) => {
            let a = store.accessor(i)?;
            Some((a.floats::<4>(store)?, a.at))
        }
        None => None,
    };
    let counts: Vec<(usize, &str)> = [t.as_ref().map(|(v, at)| (v.len(), at.as_str())), s.as_ref().map(|(v, at)| (v.len(), at.as_str()))]
        .into_iter()
        .chain([r.as_ref().map(|(v, at)| (v.len(), at.as_str()))])
        .flatten()
        .collect();
    let Some(&(count, first)) = counts.first() else { return Ok(vec![world]) };
    if let Some((c, at)) = counts.iter().find(|(c, _)| *c != count) {
        return Err(format!("{}: {at} has {c} instances but {first} has {count}: every attribute gives one per instance", ext.at));
    }
    (0..count)
        .map(|k| {
            let tk = t.as_ref().map_or(DVec3::ZERO, |(v, _)| DVec3::from(v[k].map(f64::from)));
            let sk = s.as_ref().map_or(DVec3::ONE, |(v, _)| DVec3::from(v[k].map(f64::from)));
            let rk = match &r {
                Some((v, at)) => rotation(v[k].map(f64::from), &format!("{at} element {k}"))?,
                None => DQuat::IDENTITY,
            };
            Ok(world * DMat4::from_scale_rotation_translation(sk, rk, tk))
        })
        .collect()
}
