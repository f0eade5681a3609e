//! Faces to meshes: one [`TriangleMesh`] per material, each vertex (a
//! distinct position / texture coordinate / normal combination) stored
//! once, polygons covered by triangles by the even-odd rule (ear clipping
//! for a simple face; a face that crosses itself gets vertices on its
//! edges, their attributes interpolated along the edge), and missing
//! normals computed per smoothing group.

use std::collections::HashMap;

use super::reader::{Corner, NONE, ObjData};
use crate::math::{DVec2, Vec3};
use crate::mesh::{self, MeshError, TriangleMesh, triangulate_even_odd};

/// How a vertex gets its normal; part of what makes two corners the same
/// vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum NormalSource {
    /// The file's normal, by index.
    Given(u32),
    /// Averaged over the faces of this smoothing group around the vertex.
    Smooth(u32),
    /// The normal of this face alone (smoothing off).
    Flat(u32),
}

/// A face corner with how its vertex gets its normal.
type Source = (Corner, NormalSource);

/// A vertex of a mesh: a face corner, or a point at `t` along the edge
/// between two (where a face crosses itself).
#[derive(Clone, Copy)]
struct Vertex {
    from: Source,
    to: Source,
    t: f64,
}

impl Vertex {
    /// `values[from]` to `values[to]` at `t`: exactly the first for a face
    /// corner.
    fn lerp<T>(&self, value: impl Fn(&Source) -> T) -> T
    where
        T: std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
    {
        if self.t == 0.0 {
            value(&self.from)
        } else {
            value(&self.from) * (1.0 - self.t) + value(&self.to) * self.t
        }
    }
}

/// A mesh being collected.
#[derive(Default)]
struct MeshBuilder {
    vertices: HashMap<(u32, u32, NormalSource), u32>,
    corners: Vec<Vertex>,
    triangles: Vec<[u32; 3]>,
}

impl MeshBuilder {
    /// The vertex of a face corner, shared with every corner like it.
    fn vertex(&mut self, corner: Corner, source: NormalSource) -> u32 {
        let next = self.corners.len() as u32;
        *self
            .vertices
            .entry((corner.position, corner.uv, source))
            .or_insert_with(|| {
                self.corners.push(Vertex {
                    from: (corner, source),
                    to: (corner, source),
                    t: 0.0,
                });
                next
            })
    }

    /// A new vertex at `t` along the edge from `from` to `to`.
    fn between(&mut self, from: Source, to: Source, t: f64) -> u32 {
        self.corners.push(Vertex { from, to, t });
        self.corners.len() as u32 - 1
    }
}

/// One mesh for each material slot that has faces: the slot (an index
/// into [`ObjData::material_uses`], or [`NONE`]) and its mesh.
pub(super) fn build_meshes(data: &ObjData) -> Result<Vec<(u32, TriangleMesh)>, MeshError> {
    let mut builders: Vec<(u32, MeshBuilder)> = Vec::new();
    let mut builder_of_slot: HashMap<u32, usize> = HashMap::new();
    let mut points = Vec::new();
    for (face_index, face) in data.faces.iter().enumerate() {
        let corners = &data.corners[face.first as usize..(face.first + face.count) as usize];
        let slot = *builder_of_slot.entry(face.material).or_insert_with(|| {
            builders.push((face.material, MeshBuilder::default()));
            builders.len() - 1
        });
        let builder = &mut builders[slot].1;
        let smoothing = if data.smoothing_given {
            face.smoothing
        } else {
            1
        };
        let sources: Vec<Source> = corners
            .iter()
            .map(|&c| {
                let source = if c.normal != NONE {
                    NormalSource::Given(c.normal)
                } else if smoothing != 0 {
                    NormalSource::Smooth(smoothing)
                } else {
                    NormalSource::Flat(face_index as u32)
                };
                (c, source)
            })
            .collect();
        let indices: Vec<u32> = sources
            .iter()
            .map(|&(c, source)| builder.vertex(c, source))
            .collect();
        points.clear();
        points.extend(corners.iter().map(|c| data.positions[c.position as usize]));
        for triangle in triangulate_even_odd(&points) {
            let triangle = triangle.map(|corner| match corner {
                mesh::Corner::Vertex(i) => indices[i],
                mesh::Corner::OnEdge { edge, t } => {
                    let next = (edge + 1) % sources.len();
                    builder.between(sources[edge], sources[next], t)
                }
            });
            builder.triangles.push(triangle);
        }
    }
    builders
        .into_iter()
        .map(|(slot, builder)| Ok((slot, finish(data, builder)?)))
        .collect()
}

/// The mesh of a builder, with texture coordinates if any corner has them
/// and normals unless every face is flat and none has normals given.
fn finish(data: &ObjData, builder: MeshBuilder) -> Result<TriangleMesh, MeshError> {
    let corners = builder.corners;
    let positions: Vec<Vec3> = corners
        .iter()
        .map(|v| v.lerp(|(c, _)| data.positions[c.position as usize]))
        .collect();
    let any_uv = corners.iter().any(|v| v.from.0.uv != NONE);
    let any_normal = corners
        .iter()
        .any(|v| !matches!(v.from.1, NormalSource::Flat(_)));
    let normals =
        any_normal.then(|| vertex_normals(data, &corners, &positions, &builder.triangles));
    let mut mesh = TriangleMesh::new(positions, builder.triangles)?;
    if let Some(normals) = normals {
        mesh = mesh.with_normals(normals)?;
    }
    if any_uv {
        let uvs = corners
            .iter()
            .map(|v| v.lerp(|(c, _)| data.uvs.get(c.uv as usize).copied().unwrap_or(DVec2::ZERO)))
            .collect();
        mesh = mesh.with_uvs(uvs)?;
    }
    Ok(mesh)
}

/// The file's normals where given; elsewhere the average of the normals of
/// the triangles around the vertex, each weighted by its angle there (so a
/// polygon split into many triangles counts as much as one).
fn vertex_normals(
    data: &ObjData,
    corners: &[Vertex],
    positions: &[Vec3],
    triangles: &[[u32; 3]],
) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for triangle in triangles {
        let p = triangle.map(|v| positions[v as usize]);
        let Some(normal) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else {
            continue;
        };
        for k in 0..3 {
            let edge_a = p[(k + 1) % 3] - p[k];
            let edge_b = p[(k + 2) % 3] - p[k];
            let angle = edge_a.angle_between(edge_b);
            if angle.is_finite() {
                sums[triangle[k] as usize] += angle * normal;
            }
        }
    }
    let given = |(_, source): &Source| match source {
        NormalSource::Given(n) => Some(data.normals[*n as usize]),
        _ => None,
    };
    corners
        .iter()
        .zip(sums)
        .map(|(v, sum)| match (given(&v.from), given(&v.to)) {
            (Some(n), _) if v.t == 0.0 => n,
            // A vertex on a self-crossing face's edge between two given
            // normals takes their blend.
            (Some(a), Some(b)) => (a * (1.0 - v.t) + b * v.t)
                .try_normalize()
                .unwrap_or(Vec3::ZERO),
            _ => sum.try_normalize().unwrap_or(Vec3::ZERO),
        })
        .collect()
}
