//! The scene: everything needed to render one picture, whatever file format
//! it came from. Every reader (the `scene` module) produces a [`Scene`]; the
//! renderer only ever sees this.

use crate::image::ColorSpace;
use crate::limits::Held;
use crate::math::Transform;
use crate::mesh::TriangleMesh;
use crate::render::{Camera, ObjectSources, RenderSettings};
use crate::shading::{Color, Light, Material, Texture};
use crate::shape::{Shape, ShapeError};
use crate::world::{MaterialId, MeshId, Objects};

/// Everything needed to render one picture.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The viewpoint.
    pub camera: Camera,
    /// Image size and quality.
    pub settings: RenderSettings,
    /// Colour of rays that hit nothing.
    pub background: Color,
    /// Global ambient light `Ia`.
    pub ambient: Color,
    /// What the colour values of the scene (and so of its picture) mean:
    /// linear light, or display values (NFF).
    pub color_space: ColorSpace,
    /// Materials, indexed by [`MaterialId`].
    pub materials: Vec<Material>,
    /// The names the scene file gives its materials, by [`MaterialId`]
    /// (for messages); empty where a format has none.
    pub material_names: Vec<String>,
    /// Light sources.
    pub lights: Vec<Light>,
    /// The shapes and meshes placed in the world.
    pub objects: Objects,
    /// Where the scene file defines each of them (for `whitted explain`).
    pub sources: ObjectSources,
    /// What a reader charged the memory ledger for what it put in the
    /// scene, beyond what its shapes and textures hold themselves (such
    /// as the pieces of Bézier patches); given back when the scene goes.
    pub held: Held,
}

impl Scene {
    /// An empty scene seen by `camera`, with default settings, a black
    /// background, no ambient light and linear colours.
    pub fn new(camera: Camera) -> Self {
        Self {
            camera,
            settings: RenderSettings::default(),
            background: Color::ZERO,
            ambient: Color::ZERO,
            color_space: ColorSpace::Linear,
            materials: Vec::new(),
            material_names: Vec::new(),
            lights: Vec::new(),
            objects: Objects::default(),
            sources: ObjectSources::default(),
            held: Held::default(),
        }
    }

    /// Adds a light; an area light also places its glowing shape, with a
    /// material that only emits ([`crate::shading::AreaLight::glow`]), so the camera and
    /// mirrors see it (and it stops other lights' shadow rays, as the lamp
    /// it stands for would). Refused when the light's shape is degenerate.
    pub fn add_light(&mut self, light: Light) -> Result<(), ShapeError> {
        if let Light::Area(area) = &light {
            let (shape, transform) = area.glowing_shape()?;
            let glow = Material {
                ambient: Texture::default(),
                diffuse: Texture::default(),
                emission: area.glow().into(),
                ..Material::default()
            };
            let name = format!("area light {}", self.lights.len() + 1);
            let material = self.add_named_material(&name, glow);
            self.add_primitive(shape, material, transform);
        }
        self.lights.push(light);
        Ok(())
    }

    /// Adds a material and returns its id.
    pub fn add_material(&mut self, material: Material) -> MaterialId {
        self.materials.push(material);
        MaterialId((self.materials.len() - 1) as u32)
    }

    /// Adds a material called `name` (in messages) and returns its id.
    pub fn add_named_material(&mut self, name: &str, material: Material) -> MaterialId {
        let id = self.add_material(material);
        self.material_names
            .resize(self.materials.len() - 1, String::new());
        self.material_names.push(name.to_string());
        id
    }

    /// How messages name a material: `` `glass` `` where the scene file
    /// names it, else by number (`#3`, counting from 0).
    pub fn material_name(&self, id: MaterialId) -> String {
        match self.material_names.get(id.0 as usize) {
            Some(name) if !name.is_empty() => format!("`{name}`"),
            _ => format!("#{}", id.0),
        }
    }

    /// Adds a shape with a material and an object-to-world transform
    /// ([`Objects::add_primitive`]).
    pub fn add_primitive(&mut self, shape: Shape, material: MaterialId, transform: Transform) {
        self.objects.add_primitive(shape, material, transform);
    }

    /// Adds a mesh and returns its id ([`Objects::add_mesh`]).
    pub fn add_mesh(&mut self, mesh: TriangleMesh) -> MeshId {
        self.objects.add_mesh(mesh)
    }

    /// Places a mesh with a material and a transform
    /// ([`Objects::add_mesh_instance`]).
    pub fn add_mesh_instance(&mut self, mesh: MeshId, material: MaterialId, transform: Transform) {
        self.objects.add_mesh_instance(mesh, material, transform);
    }
}
