//! The UART's byte queues between interrupt and loop (`firmware::serial`), and the loop's
//! reaction to line errors (`board::pump` resynchronises the frame decoder), on the host: the
//! test plays the interrupt handler, `pump` the control loop.

use auv_link::{encode, Command, Envelope, Msg, MAX_FRAME};
use embedded_io::{Read, ReadReady, Write};
use firmware::board::{pump, LinkBuffers};
use firmware::serial::{self, IrqSide, LineError, RxFlags, RxQueue, TxQueue, RX_CAPACITY};
use firmware::supervisor::Supervisor;

mod common;

const CLEAN: RxFlags = RxFlags {
    byte: true,
    damaged: false,
    overrun: false,
};

/// One complete frame on the wire (a harmless command; `seq` makes each distinct).
fn frame(seq: u16) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    let n = encode(&Envelope::new(seq, Msg::Command(Command::Arm)), &mut out).unwrap();
    out[..n].to_vec()
}

fn receive(irq: &mut IrqSide, bytes: &[u8]) {
    for &b in bytes {
        irq.received(CLEAN, b);
    }
}

use common::supervisor;

/// (frames accepted, receive errors) so far.
fn counts(sup: &mut Supervisor) -> (u32, u32) {
    let t = sup.step(false, &|| 0).telemetry;
    (t.rx_frames, t.rx_errors)
}

#[test]
fn bytes_come_out_in_order_whatever_the_read_size() {
    let (mut rx, mut tx) = (RxQueue::new(), TxQueue::new());
    let (mut irq, mut port) = serial::split(&mut rx, &mut tx);
    let sent: Vec<u8> = (0..300u32).map(|i| (i * 7 % 256) as u8).collect();
    receive(&mut irq, &sent);
    let mut got = Vec::new();
    let mut buf = [0u8; 7];
    while port.read_ready().unwrap() {
        let n = port.read(&mut buf).unwrap();
        assert!(n > 0);
        got.extend_from_slice(&buf[..n]);
    }
    assert_eq!(got, sent);
    assert_eq!((irq.dropped(), irq.line_errors()), (0, 0));
}

#[test]
fn a_line_error_comes_out_between_the_bytes_around_it() {
    let (mut rx, mut tx) = (RxQueue::new(), TxQueue::new());
    let (mut irq, mut port) = serial::split(&mut rx, &mut tx);
    receive(&mut irq, &[1, 2, 3]);
    irq.received(
        RxFlags {
            damaged: true,
            ..CLEAN
        },
        4,
    );
    receive(&mut irq, &[5]);
    let mut buf = [0u8; 16];
    assert_eq!(port.read(&mut buf), Ok(3));
    assert_eq!(&buf[..3], &[1, 2, 3]);
    // The damaged byte: the error first, then the byte itself.
    assert_eq!(port.read(&mut buf), Err(LineError));
    assert_eq!(port.read(&mut buf), Ok(2));
    assert_eq!(&buf[..2], &[4, 5]);
    assert!(!port.read_ready().unwrap());
    // An overrun: the byte read with it first, then the error (the lost byte came after it).
    irq.received(
        RxFlags {
            overrun: true,
            ..CLEAN
        },
        6,
    );
    assert_eq!(port.read(&mut buf), Ok(1));
    assert_eq!(buf[0], 6);
    assert_eq!(port.read(&mut buf), Err(LineError));
    assert_eq!(irq.line_errors(), 2);
}

#[test]
fn clean_frames_reach_the_supervisor() {
    let (mut rx, mut tx) = (RxQueue::new(), TxQueue::new());
    let (mut irq, mut port) = serial::split(&mut rx, &mut tx);
    let mut sup = supervisor();
    let mut bufs = LinkBuffers::new();
    receive(&mut irq, &[frame(1), frame(2), frame(3)].concat());
    pump(&mut port, &mut sup, &mut bufs);
    assert_eq!(counts(&mut sup), (3, 0));
}

#[test]
fn a_damaged_byte_drops_its_frame_even_when_the_bytes_check_out() {
    // The UART flags a byte (noise) whose value happens to be right: without the resync the
    // frame would pass its CRC and be acted on.
    let (mut rx, mut tx) = (RxQueue::new(), TxQueue::new());
    let (mut irq, mut port) = serial::split(&mut rx, &mut tx);
    let mut sup = supervisor();
    let mut bufs = LinkBuffers::new();
    let a = frame(1);
    receive(&mut irq, &a[..3]);
    irq.received(
        RxFlags {
            damaged: true,
            ..CLEAN
        },
        a[3],
    );
    receive(&mut irq, &a[4..]);
    receive(&mut irq, &frame(2));
    pump(&mut port, &mut sup, &mut bufs);
    // Frame 2 only; the line error is the one receive error.
    assert_eq!(counts(&mut sup), (1, 1));
}

#[test]
fn an_overrun_on_a_delimiter_keeps_that_frame_and_drops_the_broken_next_one() {
    // The byte in the data register (frame 1's delimiter) is good; the byte after it (frame 2's
    // first) was lost. Frame 1 stands, frame 2's remains are dropped silently, frame 3 decodes.
    let (mut rx, mut tx) = (RxQueue::new(), TxQueue::new());
    let (mut irq, mut port) = serial::split(&mut rx, &mut tx);
    let mut sup = supervisor();
    let mut bufs = LinkBuffers::new();
    let (a, b) = (frame(1), frame(2));
    receive(&mut irq, &a[..a.len() - 1]);
    irq.received(
        RxFlags {
            overrun: true,
            ..CLEAN
        },
        *a.last().unwrap(),
    );
    receive(&mut irq, &b[1..]);
    receive(&mut irq, &frame(3));
    pump(&mut port, &mut sup, &mut bufs);
    // Had the error gone before the delimiter, frame 1 would be lost and frame 2's tail would
    // be a second error: (1, 2).
    assert_eq!(counts(&mut sup), (2, 1));
}

#[test]
fn a_full_queue_drops_bytes_counts_them_and_the_stream_recovers() {
    let (mut rx, mut tx) = (RxQueue::new(), TxQueue::new());
    let (mut irq, mut port) = serial::split(&mut rx, &mut tx);
    let mut sup = supervisor();
    let mut bufs = LinkBuffers::new();
    // The loop stalls while more frames arrive than the queue holds.
    let len = frame(0).len();
    let stream: Vec<u8> = (0..100).flat_map(frame).collect();
    assert!(stream.len() > RX_CAPACITY + len);
    receive(&mut irq, &stream);
    assert_eq!(irq.dropped() as usize, stream.len() - RX_CAPACITY);
    pump(&mut port, &mut sup, &mut bufs);
    let kept = RX_CAPACITY / len;
    assert_eq!(counts(&mut sup), (kept as u32, 0));
    // The stream goes on. What arrives first after the loss is taken as the middle of a frame:
    // dropped up to its delimiter (frame 200). Frame 201 decodes; the loss is one error.
    receive(&mut irq, &[frame(200), frame(201)].concat());
    pump(&mut port, &mut sup, &mut bufs);
    assert_eq!(counts(&mut sup), (kept as u32 + 1, 1));
}

#[test]
fn written_bytes_go_out_in_order_and_a_full_queue_takes_what_fits() {
    let (mut rx, mut tx) = (RxQueue::new(), TxQueue::new());
    let (mut irq, mut port) = serial::split(&mut rx, &mut tx);
    assert_eq!(irq.next_tx(), None);
    let a = frame(7);
    port.write_all(&a).unwrap();
    assert!(!port.tx_empty());
    let sent: Vec<u8> = std::iter::from_fn(|| irq.next_tx()).collect();
    assert_eq!(sent, a);
    assert!(port.tx_empty());
    port.flush().unwrap();
    // More than the queue holds: `write` takes what fits and says so.
    let big = vec![0x55u8; serial::TX_CAPACITY + 100];
    assert_eq!(port.write(&big), Ok(serial::TX_CAPACITY));
    assert_eq!(
        std::iter::from_fn(|| irq.next_tx()).count(),
        serial::TX_CAPACITY
    );
}
