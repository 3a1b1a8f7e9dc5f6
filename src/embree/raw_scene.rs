//! An owned `RTCScene` handle and the geometries raypack attaches to it:
//! triangle meshes, sphere sets, instances of a child scene, and user
//! geometry already made on the device. [`EmbreeScene`](crate::embree::EmbreeScene)
//! builds on it, and so does the hit-record layout probe.

use glam::{Mat4, Vec3};

use embree4_sys as sys;

use crate::embree::EmbreeError;
use crate::embree::device::Device;

/// An owned `RTCScene` handle, released on drop.
pub(crate) struct RawScene(sys::RTCScene);

impl RawScene {
    /// A new, empty scene.
    pub(crate) fn new(device: &Device) -> Result<Self, EmbreeError> {
        // SAFETY: a valid device.
        let raw = unsafe { sys::rtcNewScene(device.raw()) };
        device.check("creating a scene")?;
        Ok(Self(raw))
    }

    /// The raw handle.
    #[inline]
    pub(crate) fn raw(&self) -> sys::RTCScene {
        self.0
    }

    /// Commit `geom`, attach it under the next id `id`, and drop our reference.
    pub(crate) fn attach(&self, device: &Device, geom: sys::RTCGeometry, id: u32) -> Result<(), EmbreeError> {
        // SAFETY: a geometry made on this scene's device; the scene keeps its own reference.
        unsafe {
            sys::rtcCommitGeometry(geom);
            sys::rtcAttachGeometryByID(self.0, geom, id);
            sys::rtcReleaseGeometry(geom);
        }
        device.check("attaching a geometry")
    }

    /// A new Embree-owned buffer of `count` items of `stride` bytes, as a slice of `T`.
    ///
    /// # Safety
    /// `geom` is a valid geometry, `T` has `stride` bytes, and the slice is not
    /// used after the geometry is released.
    unsafe fn buffer<'g, T>(
        device: &Device,
        geom: sys::RTCGeometry,
        kind: sys::RTCBufferType,
        format: sys::RTCFormat,
        count: usize,
    ) -> Result<&'g mut [T], EmbreeError> {
        let stride = std::mem::size_of::<T>();
        // SAFETY: valid geometry; Embree returns `count·stride` bytes, aligned for
        // its own 16-byte loads, or null on failure.
        let ptr = unsafe { sys::rtcSetNewGeometryBuffer(geom, kind, 0, format, stride, count) };
        device.check("allocating a geometry buffer")?;
        if ptr.is_null() {
            return Err(EmbreeError::Api {
                step: "allocating a geometry buffer",
                message: "null buffer".into(),
            });
        }
        // SAFETY: see above; 4-byte aligned at least, `count` items of `T`.
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr as *mut T, count) })
    }

    /// Attach a triangle mesh under id `id`.
    pub(crate) fn attach_triangles(
        &self,
        device: &Device,
        triangles: &[[Vec3; 3]],
        id: u32,
    ) -> Result<(), EmbreeError> {
        // SAFETY: valid device; buffers filled before the geometry is committed.
        unsafe {
            let geom = sys::rtcNewGeometry(device.raw(), sys::RTCGeometryType::TRIANGLE);
            let vertices: &mut [[f32; 3]] = Self::buffer(
                device,
                geom,
                sys::RTCBufferType::VERTEX,
                sys::RTCFormat::FLOAT3,
                3 * triangles.len(),
            )?;
            for (slot, v) in vertices.iter_mut().zip(triangles.iter().flatten()) {
                *slot = v.to_array();
            }
            let indices: &mut [[u32; 3]] = Self::buffer(
                device,
                geom,
                sys::RTCBufferType::INDEX,
                sys::RTCFormat::UINT3,
                triangles.len(),
            )?;
            for (i, slot) in indices.iter_mut().enumerate() {
                let first = 3 * i as u32;
                *slot = [first, first + 1, first + 2];
            }
            self.attach(device, geom, id)
        }
    }

    /// Attach spheres (`SPHERE_POINT`: centre and radius per point) under id `id`.
    pub(crate) fn attach_spheres(
        &self,
        device: &Device,
        spheres: &[(Vec3, f32)],
        id: u32,
    ) -> Result<(), EmbreeError> {
        // SAFETY: as for `attach_triangles`.
        unsafe {
            let geom = sys::rtcNewGeometry(device.raw(), sys::RTCGeometryType::SPHERE_POINT);
            let points: &mut [[f32; 4]] = Self::buffer(
                device,
                geom,
                sys::RTCBufferType::VERTEX,
                sys::RTCFormat::FLOAT4,
                spheres.len(),
            )?;
            for (slot, (c, r)) in points.iter_mut().zip(spheres) {
                *slot = [c.x, c.y, c.z, *r];
            }
            self.attach(device, geom, id)
        }
    }

    /// Attach an instance of `child` placed by `to_world` under id `id`.
    pub(crate) fn attach_instance(
        &self,
        device: &Device,
        child: &RawScene,
        to_world: Mat4,
        id: u32,
    ) -> Result<(), EmbreeError> {
        let columns = to_world.to_cols_array();
        // SAFETY: valid device and committed child scene; Embree copies the matrix.
        unsafe {
            let geom = sys::rtcNewGeometry(device.raw(), sys::RTCGeometryType::INSTANCE);
            sys::rtcSetGeometryInstancedScene(geom, child.0);
            sys::rtcSetGeometryTransform(
                geom,
                0,
                sys::RTCFormat::FLOAT4X4_COLUMN_MAJOR,
                columns.as_ptr() as *const std::ffi::c_void,
            );
            self.attach(device, geom, id)
        }
    }

    /// Build the scene's BVH.
    pub(crate) fn commit(&self, device: &Device, step: &'static str) -> Result<(), EmbreeError> {
        // SAFETY: a valid scene whose geometries are committed.
        unsafe { sys::rtcCommitScene(self.0) };
        device.check(step)
    }
}

impl Drop for RawScene {
    fn drop(&mut self) {
        // SAFETY: made by rtcNewScene, released once.
        unsafe { sys::rtcReleaseScene(self.0) };
    }
}
