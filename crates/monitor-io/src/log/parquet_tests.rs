//! Tests of the Parquet reader's row hand-over ([`super::hand_rows`]).

use super::*;

/// [`hand_rows`] (in blocks, [`RowSink::rows`], to a closure's [`OnRow`]) or
/// [`hand_ragged_rows`].
type Hand = fn(&Decoded, &ColumnMap, &mut u64, &mut dyn FnMut(&Row) -> bool) -> bool;

/// [`hand_rows`] to a closure.
fn hand_rows_to(
    cols: &Decoded,
    columns: &ColumnMap,
    handed: &mut u64,
    on_row: &mut dyn FnMut(&Row) -> bool,
) -> bool {
    hand_rows(cols, columns, handed, &mut OnRow(on_row))
}

/// The rows `hand` gives of `cols` with `columns`, bit by bit (Debug of the bits).
fn handed(
    hand: Hand,
    cols: &Decoded,
    columns: &ColumnMap,
    stop_at: usize,
) -> (Vec<String>, u64, bool) {
    let mut out = Vec::new();
    let mut n = 0u64;
    let bits = |x: f64| x.to_bits();
    let went_on = hand(cols, columns, &mut n, &mut |r: &Row| {
        out.push(format!(
            "{} {:?} {:?} {:?} {:?} {:?}",
            bits(r.t_s),
            r.v_abc.map(|v| v.map(bits)),
            r.i_abc.map(bits),
            r.wm_rad_s.map(bits),
            r.enc_count,
            r.t_winding_c.map(bits)
        ));
        out.len() < stop_at
    });
    (out, n, went_on)
}

/// The columns' rows by the specialised path are the general path's, to the last bit,
/// with and without units to convert, with columns left out (the time too), and when
/// the consumer stops early (in a block of rows too); a truncated column takes the general path.
#[test]
fn specialised_rows_are_the_general_rows() {
    // (Across blocks of rows handed over at once.)
    const ROWS: usize = 2 * HAND_ROWS + 7;
    let value = |k: usize, i: usize| (k as f64 + 1.0) * 1.37 - (i as f64) * 0.61 + 1e-3;
    for names in [
        &[
            "t_s",
            "va_V",
            "vb_V",
            "vc_V",
            "ia_A",
            "ib_A",
            "ic_A",
            "wm_rad_s",
            "enc_count",
        ][..],
        &["ia_A", "ib_A", "ic_A", "t_winding_c"][..],
        &["t_s", "ia_A", "ib_A", "ic_A", "enc_count"][..],
    ] {
        let found: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        let mut columns = ColumnMap::locate(&found, &ColumnMapping::default(), "test").unwrap();
        let mut cols: Decoded = Default::default();
        for (k, c) in cols.iter_mut().enumerate() {
            if columns.field[k].is_some() {
                *c = (0..ROWS).map(|i| value(k, i)).collect();
            }
        }
        for scaled in [false, true] {
            if scaled {
                columns.scale = std::array::from_fn(|k| 1.0 + 0.1 * k as f64);
                columns.temp_offset = 273.15;
                columns.scaled = true;
            }
            for stop_at in [usize::MAX, 3, HAND_ROWS + 5] {
                let fast = handed(hand_rows_to, &cols, &columns, stop_at);
                let general = handed(hand_ragged_rows, &cols, &columns, stop_at);
                assert_eq!(fast, general, "{names:?} scaled {scaled}");
                assert_eq!(fast.0.len(), ROWS.min(stop_at));
                assert_eq!(fast.1, ROWS.min(stop_at) as u64);
                assert_eq!(fast.2, stop_at > ROWS);
            }
        }
        // A truncated present column: the general path (its last value kept).
        let last = cols.iter().rposition(|c| !c.is_empty()).unwrap();
        cols[last].truncate(4);
        let fast = handed(hand_rows_to, &cols, &columns, usize::MAX);
        assert_eq!(fast, handed(hand_ragged_rows, &cols, &columns, usize::MAX));
        assert_eq!(fast.1, ROWS as u64);
    }
}
