//! A hand-written little-endian CDR encoder for the two messages replay writes with every state
//! (`/tf` and the contact markers). Through serde (`cdr_encoding`) they cost some 10 µs per
//! state, each primitive a `Write` call and each padding byte another; this writes straight into
//! one reused buffer. The bytes are the same (tested against `encode_cdr_le`).

use crate::msgs::{ColorRgba, Header, Marker, MarkerArray, Point, TfMessage};

/// A message being encoded: the 4-byte encapsulation header, then the payload. Alignment counts
/// from the payload's first byte, as CDR wants.
pub(crate) struct CdrWriter<'a> {
    buf: &'a mut Vec<u8>,
}

impl<'a> CdrWriter<'a> {
    /// Starts a message in `buf` (cleared).
    pub(crate) fn new(buf: &'a mut Vec<u8>) -> CdrWriter<'a> {
        buf.clear();
        buf.extend_from_slice(&[0x00, 0x01, 0x00, 0x00]);
        CdrWriter { buf }
    }

    fn align(&mut self, n: usize) {
        let pad = (n - (self.buf.len() - 4) % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn f64s(&mut self, v: &[f64]) {
        self.align(8);
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
    }

    fn bool(&mut self, v: bool) {
        self.buf.push(v as u8);
    }

    fn len(&mut self, n: usize) {
        // Sequences this crate builds hold far fewer than 2^32 elements.
        self.u32(n as u32);
    }

    fn string(&mut self, s: &str) {
        self.len(s.len() + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    fn bytes(&mut self, b: &[u8]) {
        self.len(b.len());
        self.buf.extend_from_slice(b);
    }

    fn header(&mut self, h: &Header) {
        self.i32(h.stamp.sec);
        self.u32(h.stamp.nanosec);
        self.string(&h.frame_id);
    }

    fn point(&mut self, p: &Point) {
        self.f64s(&[p.x, p.y, p.z]);
    }

    fn color(&mut self, c: &ColorRgba) {
        for v in [c.r, c.g, c.b, c.a] {
            self.f32(v);
        }
    }

    /// `tf2_msgs/TFMessage`.
    pub(crate) fn tf_message(mut self, m: &TfMessage) {
        self.len(m.transforms.len());
        for t in &m.transforms {
            self.header(&t.header);
            self.string(&t.child_frame_id);
            let (v, q) = (t.transform.translation, t.transform.rotation);
            self.f64s(&[v.x, v.y, v.z, q.x, q.y, q.z, q.w]);
        }
    }

    /// `visualization_msgs/MarkerArray` (the Iron/Jazzy `Marker`).
    pub(crate) fn marker_array(mut self, a: &MarkerArray) {
        self.len(a.markers.len());
        for m in &a.markers {
            self.marker(m);
        }
    }

    fn marker(&mut self, m: &Marker) {
        self.header(&m.header);
        self.string(&m.ns);
        self.i32(m.id);
        self.i32(m.kind);
        self.i32(m.action);
        let (p, o) = (m.pose.position, m.pose.orientation);
        self.f64s(&[p.x, p.y, p.z, o.x, o.y, o.z, o.w]);
        self.point(&m.scale);
        self.color(&m.color);
        self.i32(m.lifetime.sec);
        self.u32(m.lifetime.nanosec);
        self.bool(m.frame_locked);
        self.len(m.points.len());
        for p in &m.points {
            self.point(p);
        }
        self.len(m.colors.len());
        for c in &m.colors {
            self.color(c);
        }
        self.string(&m.texture_resource);
        self.header(&m.texture.header);
        self.string(&m.texture.format);
        self.bytes(&m.texture.data);
        self.len(m.uv_coordinates.len());
        for uv in &m.uv_coordinates {
            self.f32(uv.u);
            self.f32(uv.v);
        }
        self.string(&m.text);
        self.string(&m.mesh_resource);
        self.string(&m.mesh_file.filename);
        self.bytes(&m.mesh_file.data);
        self.bool(m.mesh_use_embedded_materials);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::{DurationMsg, Time, Transform, TransformStamped, UvCoordinate, Vector3};
    use crate::replay::encode_cdr_le;

    #[test]
    fn the_same_bytes_as_serde() {
        let header = |s: &str| Header { stamp: Time { sec: 17, nanosec: 3 }, frame_id: s.into() };
        let tf = TfMessage {
            transforms: (0..3)
                .map(|i| TransformStamped {
                    header: header("world"),
                    child_frame_id: "link_".repeat(i + 1),
                    transform: Transform { translation: Vector3 { x: 1.5, y: -2.0, z: i as f64 }, ..Default::default() },
                })
                .collect(),
        };
        let mut buf = Vec::new();
        CdrWriter::new(&mut buf).tf_message(&tf);
        assert_eq!(buf, encode_cdr_le(&tf));
        let marker = |k: usize| Marker {
            header: header(&"w".repeat(k)),
            ns: "contacts".into(),
            id: k as i32,
            kind: 7,
            action: 3,
            lifetime: DurationMsg { sec: 1, nanosec: 2 },
            frame_locked: k.is_multiple_of(2),
            points: vec![Point { x: 0.1, y: 0.2, z: 0.3 }; k],
            colors: vec![ColorRgba { r: 1.0, g: 0.5, b: 0.0, a: 1.0 }; k],
            uv_coordinates: vec![UvCoordinate { u: 0.5, v: 0.25 }; k % 3],
            text: "forearm x guard".repeat(k),
            mesh_use_embedded_materials: true,
            ..Default::default()
        };
        let array = MarkerArray { markers: (0..5).map(marker).collect() };
        CdrWriter::new(&mut buf).marker_array(&array);
        assert_eq!(buf, encode_cdr_le(&array));
        CdrWriter::new(&mut buf).marker_array(&MarkerArray::default());
        assert_eq!(buf, encode_cdr_le(&MarkerArray::default()));
    }
}
