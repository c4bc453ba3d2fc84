// Decodes one nadir pose_t from the file named, with nadir's Java types, and
// prints its fields one a line (Double.toString: the shortest text that reads
// back to the same double).
import java.nio.file.Files;
import java.nio.file.Paths;

public class PoseDecode {
  static void print(String name, double[] values) {
    StringBuilder line = new StringBuilder(name);
    for (double value : values) line.append(' ').append(value);
    System.out.println(line);
  }

  public static void main(String[] args) throws Exception {
    nadir.pose_t pose = new nadir.pose_t(Files.readAllBytes(Paths.get(args[0])));
    System.out.println("utime " + pose.utime);
    print("pos", pose.pos);
    print("vel", pose.vel);
    print("orientation", pose.orientation);
    print("rotation_rate", pose.rotation_rate);
    print("accel", pose.accel);
  }
}
