//! Shading dictionaries of types 6 and 7: their colour space and function, and the patch
//! records of their streams, decoded bit by bit.

use kurbo::{Point, Rect};
use lopdf::Object;

use super::bits::BitReader;
use super::colour::ShadingColour;
use super::functions::read_function;
use super::objects::{invalid, Objects};
use super::scene::{coons_interior, Patch, POINT_ORDER};
use super::spaces::read_colour_space;
use crate::error::{Error, ErrorKind};

/// A shading as read, in its own coordinates.
pub(crate) struct ReadShading {
    pub shading_type: u8,
    pub patches: Vec<Patch>,
    pub colour: ShadingColour,
    /// `BBox`, in the shading's coordinates.
    pub bbox: Option<Rect>,
    /// The `Background`'s components in the shading's colour space, or why they cannot be
    /// used; `None` without one.
    pub background: Option<Result<Vec<f64>, String>>,
}

/// What a shading object is.
pub(crate) enum Shading {
    /// A patch mesh (type 6 or 7), read.
    Mesh(Box<ReadShading>),
    /// Another type, not read.
    Other(i64),
}

/// Limits of a shading's reading.
#[derive(Clone, Copy)]
pub(crate) struct ShadingLimits {
    /// The most patches of one shading.
    pub patches: u64,
    /// The most bytes of one decoded stream.
    pub bytes: u64,
}

/// Reads the shading `object` (`what` names it).
pub(crate) fn read_shading(
    objects: Objects,
    object: &Object,
    what: &str,
    limits: ShadingLimits,
) -> Result<Shading, Error> {
    let dict = objects.dict(object, what)?;
    let kind = objects
        .get(dict, b"ShadingType", what)?
        .ok_or_else(|| invalid(what, "the shading has no ShadingType"))?;
    let kind = objects.number(kind, &format!("{what} /ShadingType"))?;
    if kind != 6.0 && kind != 7.0 {
        return Ok(Shading::Other(kind as i64));
    }
    let shading_type = kind as u8;
    let space_object = objects
        .get(dict, b"ColorSpace", what)?
        .ok_or_else(|| invalid(what, "the shading has no ColorSpace"))?;
    let space = read_colour_space(objects, space_object, &format!("{what} /ColorSpace"))?;
    let function = match objects.get(dict, b"Function", what)? {
        Some(f) => Some(read_function(objects, f, &format!("{what} /Function"), 1)?),
        None => None,
    };
    let colour = ShadingColour { space, function };
    let bbox = match objects.get(dict, b"BBox", what)? {
        Some(b) => {
            let n = objects.numbers(b, &format!("{what} /BBox"))?;
            if n.len() != 4 {
                return Err(invalid(format!("{what} /BBox"), "expected 4 numbers"));
            }
            Some(Rect::new(n[0], n[1], n[2], n[3]).abs())
        }
        None => None,
    };
    let background = match objects.get(dict, b"Background", what)? {
        Some(b) => Some(background_components(
            objects,
            b,
            &colour,
            &format!("{what} /Background"),
        )?),
        None => None,
    };
    let layout = RecordLayout::read(objects, dict, &colour, shading_type, what)?;
    let stream = objects.stream(object, what)?;
    let data = objects.stream_data(stream, what, limits.bytes)?;
    let patches = decode_patches(&data, &layout, limits.patches, what)?;
    Ok(Shading::Mesh(Box::new(ReadShading {
        shading_type,
        patches,
        colour,
        bbox,
        background,
    })))
}

/// The components of the `Background` array `object`: as many as the colour space has (a
/// `Function` does not apply to them); of another number, the reason it is not used, as
/// poppler leaves such a background out.
fn background_components(
    objects: Objects,
    object: &Object,
    colour: &ShadingColour,
    what: &str,
) -> Result<Result<Vec<f64>, String>, Error> {
    let components = objects.numbers(object, what)?;
    let expected = colour.space.components();
    Ok(if components.len() == expected {
        Ok(components)
    } else {
        Err(format!(
            "{what} has {} numbers where its colour space has {expected} components",
            components.len()
        ))
    })
}

/// The layout of a shading's patch records.
struct RecordLayout {
    points: usize,
    coordinate_bits: u32,
    component_bits: u32,
    flag_bits: u32,
    /// Components per corner.
    components: usize,
    /// `[x, y, c1, ...]` ranges.
    decode: Vec<[f64; 2]>,
}

impl RecordLayout {
    fn read(
        objects: Objects,
        dict: &lopdf::Dictionary,
        colour: &ShadingColour,
        shading_type: u8,
        what: &str,
    ) -> Result<RecordLayout, Error> {
        let bits = |key: &[u8], allowed: &[u32]| -> Result<u32, Error> {
            let label = format!("{what} /{}", String::from_utf8_lossy(key));
            let value = objects.get(dict, key, what)?.ok_or_else(|| {
                invalid(
                    what,
                    format!("the shading has no {}", String::from_utf8_lossy(key)),
                )
            })?;
            let value = objects.number(value, &label)?;
            allowed
                .iter()
                .copied()
                .find(|&a| f64::from(a) == value)
                .ok_or_else(|| invalid(label, format!("{value} is not one of {allowed:?}")))
        };
        let coordinate_bits = bits(b"BitsPerCoordinate", &[1, 2, 4, 8, 12, 16, 24, 32])?;
        let component_bits = bits(b"BitsPerComponent", &[1, 2, 4, 8, 12, 16])?;
        let flag_bits = bits(b"BitsPerFlag", &[2, 4, 8])?;
        let components = colour.corner_components();
        let decode = objects
            .get(dict, b"Decode", what)?
            .ok_or_else(|| invalid(what, "the shading has no Decode"))?;
        let decode = objects.numbers(decode, &format!("{what} /Decode"))?;
        if decode.len() != 4 + 2 * components {
            return Err(invalid(
                format!("{what} /Decode"),
                format!(
                    "expected {} numbers (x and y ranges, then {components} component range{}), found {}",
                    4 + 2 * components,
                    if components == 1 { "" } else { "s" },
                    decode.len()
                ),
            ));
        }
        Ok(RecordLayout {
            points: if shading_type == 6 { 12 } else { 16 },
            coordinate_bits,
            component_bits,
            flag_bits,
            components,
            decode: decode.chunks(2).map(|p| [p[0], p[1]]).collect(),
        })
    }

    /// The bits of a record with `points` points and `corners` colours.
    fn record_bits(&self, points: usize, corners: usize) -> u64 {
        u64::from(self.flag_bits)
            + 2 * points as u64 * u64::from(self.coordinate_bits)
            + (corners * self.components) as u64 * u64::from(self.component_bits)
    }
}

/// Corner colours in stream order (c00, c03, c33, c30) as indices of [`Patch::components`]
/// corners ((0, 0), (0, 1), (1, 0), (1, 1)).
const CORNER_ORDER: [usize; 4] = [0, 1, 3, 2];

/// Decodes the patch records of `data`. Each record starts on a byte boundary, as poppler
/// and Ghostscript read them. The number of patches the data can hold at most is checked
/// against `max_patches` before any is stored; zero bytes after the last whole record are
/// padding.
fn decode_patches(
    data: &[u8],
    layout: &RecordLayout,
    max_patches: u64,
    what: &str,
) -> Result<Vec<Patch>, Error> {
    let shortest = layout.record_bits(layout.points - 4, 2).div_ceil(8) * 8;
    let most = data.len() as u64 * 8 / shortest;
    if most > max_patches {
        return Err(ErrorKind::LimitExceeded {
            what: format!("the patches {what} can hold"),
            found: most,
            limit: max_patches,
        }
        .into());
    }
    let mut reader = BitReader::new(data);
    let mut patches: Vec<Patch> = Vec::with_capacity(most as usize);
    while reader.remaining() > 0 {
        let start = reader.byte_position();
        if data[start as usize..].iter().all(|&b| b == 0)
            && reader.remaining() < layout.record_bits(layout.points, 4)
        {
            break;
        }
        let patch = decode_record(&mut reader, layout, patches.last()).map_err(|message| {
            invalid(
                what,
                format!(
                    "patch {} (at byte {start} of {}): {message}",
                    patches.len(),
                    data.len()
                ),
            )
        })?;
        patches.push(patch);
        reader.align();
    }
    if patches.is_empty() {
        return Err(invalid(what, "the shading's stream holds no patch"));
    }
    Ok(patches)
}

/// Decodes one record, sharing a side with `previous` when its flag says so.
fn decode_record(
    reader: &mut BitReader,
    layout: &RecordLayout,
    previous: Option<&Patch>,
) -> Result<Patch, String> {
    let truncated = || "the stream ends inside the patch".to_string();
    let flag = reader.read(layout.flag_bits).ok_or_else(truncated)? & 3;
    let mut points = [[Point::ZERO; 4]; 4];
    let n = layout.components;
    let mut components = vec![0.0; 4 * n];
    let (first_point, first_corner) = if flag == 0 {
        (0, 0)
    } else {
        let previous = previous.ok_or_else(|| {
            format!("the first patch shares a side (edge flag {flag}) with no patch before it")
        })?;
        let p = &previous.points;
        let side = match flag {
            1 => [p[0][3], p[1][3], p[2][3], p[3][3]],
            2 => [p[3][3], p[3][2], p[3][1], p[3][0]],
            _ => [p[3][0], p[2][0], p[1][0], p[0][0]],
        };
        for (k, q) in side.into_iter().enumerate() {
            points[0][k] = q;
        }
        // The previous patch's corners in stream order: c00, c03, c33, c30.
        let corner = |s: usize| &previous.components[CORNER_ORDER[s] * n..CORNER_ORDER[s] * n + n];
        let (a, b) = match flag {
            1 => (corner(1), corner(2)),
            2 => (corner(2), corner(3)),
            _ => (corner(3), corner(0)),
        };
        components[..n].copy_from_slice(a);
        components[CORNER_ORDER[1] * n..CORNER_ORDER[1] * n + n].copy_from_slice(b);
        (4, 2)
    };
    let coordinate = |reader: &mut BitReader, range: [f64; 2], bits: u32| {
        let raw = reader.read(bits).ok_or_else(truncated)?;
        let max = ((1u64 << bits) - 1) as f64;
        Ok::<f64, String>(range[0] + raw as f64 * (range[1] - range[0]) / max)
    };
    for &(i, j) in &POINT_ORDER[first_point..layout.points] {
        let x = coordinate(reader, layout.decode[0], layout.coordinate_bits)?;
        let y = coordinate(reader, layout.decode[1], layout.coordinate_bits)?;
        points[i][j] = Point::new(x, y);
    }
    for &corner in &CORNER_ORDER[first_corner..] {
        for k in 0..n {
            components[corner * n + k] =
                coordinate(reader, layout.decode[2 + k], layout.component_bits)?;
        }
    }
    if layout.points == 12 {
        coons_interior(&mut points);
    }
    Ok(Patch { points, components })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(points: usize) -> RecordLayout {
        RecordLayout {
            points,
            coordinate_bits: 8,
            component_bits: 8,
            flag_bits: 8,
            components: 1,
            decode: vec![[0.0, 255.0], [0.0, 255.0], [0.0, 1.0]],
        }
    }

    /// A type 6 record with flag 0, then one with flag 2 sharing the previous third side.
    #[test]
    fn edge_flags_share_the_previous_side() {
        let mut data = vec![0u8];
        let first: [(u8, u8); 12] = [
            (0, 0),
            (0, 10),
            (0, 20),
            (0, 30),
            (10, 30),
            (20, 30),
            (30, 30),
            (30, 20),
            (30, 10),
            (30, 0),
            (20, 0),
            (10, 0),
        ];
        data.extend(first.iter().flat_map(|&(x, y)| [x, y]));
        data.extend([0, 51, 102, 153]);
        data.push(2);
        let second: [(u8, u8); 8] = [
            (40, 30),
            (50, 30),
            (60, 30),
            (60, 20),
            (60, 10),
            (60, 0),
            (50, 0),
            (40, 0),
        ];
        data.extend(second.iter().flat_map(|&(x, y)| [x, y]));
        data.extend([204, 255]);
        let patches = decode_patches(&data, &layout(12), 100, "object 1").unwrap();
        assert_eq!(patches.len(), 2);
        let (a, b) = (&patches[0], &patches[1]);
        // Flag 2: the new p00..p03 are the previous p33, p32, p31, p30.
        assert_eq!(b.points[0][0], a.points[3][3]);
        assert_eq!(b.points[0][3], a.points[3][0]);
        assert_eq!(b.points[3][3], Point::new(60.0, 30.0));
        // Its c00 and c03 are the previous c33 and c30; c33, c30 come from the record.
        let t = |v: u8| f64::from(v) / 255.0;
        assert_eq!(a.components, vec![t(0), t(51), t(153), t(102)]);
        assert_eq!(b.components, vec![t(102), t(153), t(255), t(204)]);
    }

    #[test]
    fn truncated_and_oversized_streams_are_refused() {
        let mut data = vec![0u8];
        data.extend([7u8; 30]);
        let e = decode_patches(&data, &layout(16), 100, "object 9").unwrap_err();
        assert!(
            e.to_string().contains("object 9") && e.to_string().contains("ends inside"),
            "{e}"
        );
        let e = decode_patches(&vec![0u8; 10_000], &layout(16), 10, "object 9").unwrap_err();
        assert!(e.to_string().contains("above the limit of 10"), "{e}");
        let mut data = vec![1u8];
        data.extend([7u8; 40]);
        let e = decode_patches(&data, &layout(16), 100, "object 9").unwrap_err();
        assert!(e.to_string().contains("no patch before it"), "{e}");
        assert!(decode_patches(&[0u8; 3], &layout(16), 100, "object 9")
            .unwrap_err()
            .to_string()
            .contains("holds no patch"));
    }
}
