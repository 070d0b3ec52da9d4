//! The compressed image data of an 8-bit PNG, encoded on every core.
//!
//! PNG holds its image as one zlib stream, which `png` compresses on one thread. Here the rows
//! are cut into segments of a fixed size, each compressed on its own (in parallel) into a
//! deflate block that ends on a byte boundary, so that the blocks join into one stream; their
//! Adler-32 checksums are combined. Each segment becomes an `IDAT` chunk. The segments depend
//! only on the image, never on the thread count: the file's bytes are the same on any number
//! of threads.
//!
//! The compression is the `png` crate's fast setting: every row with the Sub filter, then
//! fdeflate, one fixed Huffman code tuned for filtered images. fdeflate writes a whole zlib
//! stream whose one block is final and ends at any bit; a segment's block is made part of a
//! longer stream by clearing its final bit and ending it with an empty stored block (a sync
//! flush), which needs the bit where its end-of-block code ends: the last bit set is the last
//! set bit of that code, whose bits are known. A segment that would not shrink is stored
//! instead.

use rayon::prelude::*;

/// Raw bytes (filtered rows) per segment, at least: a segment holds whole rows.
const SEGMENT_BYTES: usize = 1 << 18;

/// fdeflate's code lengths: literals `0..=255`, the end of a block (256), match lengths
/// `257..=285`.
const LENGTHS: [u8; 286] = [
    2, 3, 4, 5, 5, 6, 6, 7, 7, 7, 8, 8, 8, 8, 8, 9, 9, 9, 9, 9, 9, 9, 10, 10, 10, 10, 10, 10, 10,
    10, 10, 11, 11, 11, 11, 11, 11, 11, 11, 11, 11, 11, 11, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 11, 11, 11, 11, 11, 11, 11,
    11, 11, 11, 10, 11, 10, 10, 10, 10, 10, 10, 10, 10, 10, 9, 9, 9, 9, 9, 8, 9, 8, 8, 8, 8, 8, 7,
    7, 7, 6, 6, 6, 5, 4, 3, 12, 12, 12, 9, 9, 11, 10, 11, 11, 10, 11, 11, 11, 11, 11, 11, 12, 11,
    12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 9,
];

/// The canonical codes of [`LENGTHS`], bit-reversed as deflate writes them (first bit
/// lowest).
const CODES: [u16; 286] = canonical_codes(&LENGTHS);

/// zlib's header: deflate with a 32 KiB window, the fastest level.
const ZLIB_HEADER: [u8; 2] = [0x78, 0x01];

/// The end-of-block symbol.
const END_OF_BLOCK: usize = 256;

/// The canonical Huffman codes of code lengths `lengths`, bit-reversed.
const fn canonical_codes(lengths: &[u8; 286]) -> [u16; 286] {
    let mut codes = [0u16; 286];
    let mut code = 0u32;
    let mut len = 1;
    while len <= 16 {
        let mut i = 0;
        while i < lengths.len() {
            if lengths[i] == len {
                codes[i] = (code as u16).reverse_bits() >> (16 - len);
                code += 1;
            }
            i += 1;
        }
        code <<= 1;
        len += 1;
    }
    assert!(code == 2 << 16, "the code lengths are not a complete code");
    codes
}

/// How many zero bits the end-of-block code writes after its last one bit.
const END_ZEROS: u32 = {
    let (code, len) = (CODES[END_OF_BLOCK] as u32, LENGTHS[END_OF_BLOCK] as u32);
    assert!(code != 0);
    len - (32 - code.leading_zeros())
};

/// One segment of the stream: its bytes, and the Adler-32 checksum and length of the raw
/// (filtered) bytes it holds.
pub(crate) struct Segment {
    pub bytes: Vec<u8>,
    pub adler: u32,
    pub raw_len: u64,
}

/// Compresses 8-bit RGBA `data` (rows of `row_len` bytes) into the segments of one zlib
/// stream: the first starts with the zlib header, the last ends with the stream's checksum.
/// Their concatenation is the image data of the PNG.
pub(crate) fn compress_rgba8(data: &[u8], row_len: usize) -> Vec<Segment> {
    let rows = (SEGMENT_BYTES / (row_len + 1)).max(1);
    let n = data.len().div_ceil(row_len * rows).max(1);
    let mut segments: Vec<Segment> = if data.is_empty() {
        vec![segment(&[], row_len, true)]
    } else {
        data.par_chunks(row_len * rows)
            .enumerate()
            .map(|(k, rows)| segment(rows, row_len, k + 1 == n))
            .collect()
    };
    let adler = segments
        .iter()
        .fold(1, |a, s| adler32_combine(a, s.adler, s.raw_len));
    segments[0].bytes.splice(0..0, ZLIB_HEADER);
    let last = segments.last_mut().expect("one segment at least");
    last.bytes.extend_from_slice(&adler.to_be_bytes());
    segments
}

/// Compresses rows `rows` (of `row_len` bytes): one block, the stream's last if `last`, else
/// followed by an empty stored block that ends it on a byte boundary. Stored if that is
/// smaller.
fn segment(rows: &[u8], row_len: usize, last: bool) -> Segment {
    let row_len = row_len.max(1);
    let raw_len = (rows.len() / row_len * (row_len + 1)) as u64;
    let compressed = deflate(rows, row_len).filter(|b| b.len() as u64 + 5 <= stored_size(raw_len));
    let Some(mut zlib) = compressed else {
        return stored(rows, row_len, last);
    };
    let adler = u32::from_be_bytes(zlib[zlib.len() - 4..].try_into().expect("four bytes"));
    zlib.truncate(zlib.len() - 4);
    zlib.drain(..ZLIB_HEADER.len());
    let mut bytes = zlib;
    if !last {
        // The last bit set is the last one bit of the end-of-block code.
        let Some(k) = bytes.iter().rposition(|&b| b != 0) else {
            return stored(rows, row_len, last);
        };
        let end = 8 * k as u64 + u64::from(8 - bytes[k].leading_zeros() + END_ZEROS);
        let Some(padding) = (8 * bytes.len() as u64).checked_sub(end).filter(|&p| p < 8) else {
            return stored(rows, row_len, last);
        };
        bytes[0] &= !1;
        // A stored block's three header bits (not final, type 0) fit in the padding, or take
        // one more byte; then its empty length.
        if padding < 3 {
            bytes.push(0);
        }
        bytes.extend_from_slice(&[0, 0, 0xff, 0xff]);
    }
    Segment {
        bytes,
        adler,
        raw_len,
    }
}

/// The rows Sub-filtered and compressed by fdeflate: a zlib stream of one final block.
fn deflate(rows: &[u8], row_len: usize) -> Option<Vec<u8>> {
    let mut compressor = fdeflate::Compressor::new(Vec::with_capacity(rows.len() / 3 + 64)).ok()?;
    let mut filtered = vec![0u8; row_len + 1];
    filtered[0] = 1;
    for row in rows.chunks_exact(row_len) {
        sub_filter(row, &mut filtered[1..]);
        compressor.write_data(&filtered).ok()?;
    }
    compressor.finish().ok()
}

/// The bytes of `raw_len` bytes in stored blocks.
fn stored_size(raw_len: u64) -> u64 {
    raw_len + 5 * raw_len.div_ceil(u16::MAX as u64).max(1)
}

/// Rows `rows` unfiltered (filter type 0), in stored blocks.
fn stored(rows: &[u8], row_len: usize, last: bool) -> Segment {
    let mut raw = Vec::with_capacity(rows.len() / row_len.max(1) * (row_len + 1));
    for row in rows.chunks_exact(row_len) {
        raw.push(0);
        raw.extend_from_slice(row);
    }
    let mut adler = simd_adler32::Adler32::new();
    adler.write(&raw);
    let mut bytes = Vec::with_capacity(stored_size(raw.len() as u64) as usize);
    let blocks = raw.chunks(u16::MAX as usize);
    let count = blocks.len().max(1);
    let mut put = |k: usize, block: &[u8]| {
        let len = block.len() as u16;
        bytes.push((last && k + 1 == count) as u8);
        bytes.extend_from_slice(&len.to_le_bytes());
        bytes.extend_from_slice(&(!len).to_le_bytes());
        bytes.extend_from_slice(block);
    };
    if raw.is_empty() {
        put(0, &[]);
    }
    for (k, block) in raw.chunks(u16::MAX as usize).enumerate() {
        put(k, block);
    }
    Segment {
        bytes,
        adler: adler.finish(),
        raw_len: raw.len() as u64,
    }
}

/// PNG's Sub filter of an RGBA row: each byte less the byte four before it.
#[inline(always)]
fn sub_filter(row: &[u8], out: &mut [u8]) {
    let n = row.len().min(4);
    out[..n].copy_from_slice(&row[..n]);
    for ((o, &b), &a) in out[n..].iter_mut().zip(&row[n..]).zip(row) {
        *o = b.wrapping_sub(a);
    }
}

/// The Adler-32 checksum of the bytes of `a` followed by the `len_b` bytes of `b` (zlib's
/// `adler32_combine`).
pub(crate) fn adler32_combine(a: u32, b: u32, len_b: u64) -> u32 {
    const BASE: u64 = 65521;
    let rem = len_b % BASE;
    let (a1, a2) = ((a & 0xffff) as u64, (a >> 16) as u64);
    let (b1, b2) = ((b & 0xffff) as u64, (b >> 16) as u64);
    let s1 = (a1 + b1 + BASE - 1) % BASE;
    let s2 = (rem * a1 % BASE + a2 + b2 + BASE - rem) % BASE;
    (s2 << 16 | s1) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adler(data: &[u8]) -> u32 {
        let mut a = simd_adler32::Adler32::new();
        a.write(data);
        a.finish()
    }

    #[test]
    fn combined_checksums_are_the_checksum_of_the_whole() {
        let data: Vec<u8> = (0..200_000u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        for split in [0, 1, 5552, 65521, 100_000, 200_000] {
            let (x, y) = data.split_at(split);
            let combined = adler32_combine(adler(x), adler(y), y.len() as u64);
            assert_eq!(combined, adler(&data), "split at {split}");
        }
    }

    /// The segments joined are one zlib stream that inflates to the Sub-filtered rows.
    #[test]
    fn segments_inflate_to_the_rows() {
        // Several widths, so that segments end at every bit of a byte.
        for (w, h) in [(301, 700), (64, 3000), (97, 2000), (1000, 300), (3, 5)] {
            segments_inflate_to(w, h);
        }
    }

    fn segments_inflate_to(w: usize, h: usize) {
        use std::io::Read;
        let row_len = 4 * w;
        // Smooth areas (runs of zeros once filtered), noise, and flat rows.
        let data: Vec<u8> = (0..row_len * h)
            .map(|i| {
                let (x, y) = (i % row_len, i / row_len);
                match y % 7 {
                    0 => 0,
                    1 => (i.wrapping_mul(2_654_435_761) >> 11) as u8,
                    _ => (x / 40 + y / 3) as u8,
                }
            })
            .collect();
        let segments = compress_rgba8(&data, row_len);
        let stream: Vec<u8> = segments.iter().flat_map(|s| s.bytes.clone()).collect();
        let mut raw = Vec::new();
        flate2::read::ZlibDecoder::new(&stream[..])
            .read_to_end(&mut raw)
            .unwrap();
        assert_eq!(raw.len(), h * (row_len + 1));
        // Noise rows may have been stored unfiltered: compare the unfiltered rows.
        let unfilter = |bytes: &[u8]| -> Vec<u8> {
            bytes
                .chunks_exact(row_len + 1)
                .flat_map(|r| {
                    let mut row = r[1..].to_vec();
                    if r[0] == 1 {
                        for i in 4..row.len() {
                            row[i] = row[i].wrapping_add(row[i - 4]);
                        }
                    }
                    row
                })
                .collect()
        };
        assert_eq!(unfilter(&raw), data);
    }

    /// Noise does not shrink: it is stored, and still inflates to the rows.
    #[test]
    fn incompressible_rows_are_stored() {
        use std::io::Read;
        let row_len = 4 * 5000;
        let data: Vec<u8> = (0..row_len * 20)
            .map(|i| (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15).to_le_bytes()[7])
            .collect();
        let segments = compress_rgba8(&data, row_len);
        let stream: Vec<u8> = segments.iter().flat_map(|s| s.bytes.clone()).collect();
        assert!(stream.len() < data.len() + 1000);
        let mut raw = Vec::new();
        flate2::read::ZlibDecoder::new(&stream[..])
            .read_to_end(&mut raw)
            .unwrap();
        let rows: Vec<u8> = raw
            .chunks_exact(row_len + 1)
            .flat_map(|r| {
                assert_eq!(r[0], 0);
                r[1..].to_vec()
            })
            .collect();
        assert_eq!(rows, data);
    }

    /// The bytes do not depend on the number of threads.
    #[test]
    fn segments_do_not_depend_on_the_thread_count() {
        let row_len = 4 * 640;
        let data: Vec<u8> = (0..row_len * 480).map(|i| (i / 7 % 251) as u8).collect();
        let on = |threads: usize| -> Vec<u8> {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| compress_rgba8(&data, row_len))
                .into_iter()
                .flat_map(|s| s.bytes)
                .collect()
        };
        assert_eq!(on(1), on(3));
    }
}
